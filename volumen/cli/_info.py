"""``volumen info PATH``: dimensions, spacing, orientation, value range, modality. Never patient identity."""

from __future__ import annotations

import json

import numpy as np

from ._common import add_load_options, load_from_args


def register(sub):
    p = sub.add_parser("info", help="describe a volume (no patient identity is shown)")
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    add_load_options(p)
    return p


def describe(volume) -> dict:
    """Technical facts of a volume as a JSON-able dict (no patient-identifying fields)."""
    lo, hi = volume.value_range()
    meta = volume.meta
    facts = {
        "name": volume.name,
        "format": meta.get("format", ""),
        "shape_zyx": list(volume.shape),
        "spacing_mm_zyx": [round(s, 6) for s in volume.spacing],
        "orientation": volume.orientation,
        "oblique": volume.is_oblique,
        "origin_ras_mm": [round(float(v), 4) for v in volume.origin],
        "extent_mm_xyz": [round(float(v), 3) for v in volume.extent],
        "dtype": str(volume.dtype),
        "modality": volume.modality,
        "units": volume.units,
        "value_range": [lo, hi],
        "affine": np.round(volume.affine, 6).tolist(),
        "warnings": list(meta.get("warnings", [])),
    }
    for key in ("series_uid", "series_description", "n_files", "transfer_syntax", "manufacturer"):
        if key in meta:
            facts[key] = meta[key]
    return facts


def run(args):
    vol = load_from_args(args)
    facts = describe(vol)
    if args.json:
        print(json.dumps(facts, indent=2))
        return 0
    z, y, x = facts["shape_zyx"]
    dz, dy, dx = facts["spacing_mm_zyx"]
    lines = [
        f"name:         {facts['name'] or '-'}",
        f"format:       {facts['format']}",
        f"size:         {x} x {y} x {z} voxels (x, y, z)",
        f"spacing:      {dx:g} x {dy:g} x {dz:g} mm (x, y, z)",
        f"extent:       {' x '.join(f'{v:g}' for v in facts['extent_mm_xyz'])} mm",
        f"orientation:  {facts['orientation']}{' (oblique)' if facts['oblique'] else ''} "
        f"(voxel axes i, j, k toward these patient directions)",
        f"origin:       {', '.join(f'{v:g}' for v in facts['origin_ras_mm'])} mm (RAS)",
        f"modality:     {facts['modality']}",
        f"values:       {facts['value_range'][0]:g} .. {facts['value_range'][1]:g} {facts['units']} ({facts['dtype']})",
    ]
    for key in ("series_uid", "n_files", "transfer_syntax"):
        if key in facts:
            lines.append(f"{key + ':':14}{facts[key]}")
    for w in facts["warnings"]:
        lines.append(f"warning:      {w}")
    print("\n".join(lines))
    return 0
