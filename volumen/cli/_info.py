"""``volumen info PATH``: dimensions, spacing, orientation, value range, modality. Never patient identity.

For a DICOM folder it first lists every image series (number, modality, size, files,
description, SeriesInstanceUID) and the files it skipped, like dcm2niix; the volume is
described when the folder holds one series or ``--series`` picks one.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import numpy as np

from ._common import add_load_options, load_from_args
from ._labels_opts import add_label_options, labels_from_args, shown_values


def register(sub):
    p = sub.add_parser("info", help="describe a volume (no patient identity is shown)")
    p.add_argument("input", help="volume file, DICOM folder, phantom:NAME, or dicomweb://SERVER/STUDY/SERIES")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    add_load_options(p)
    add_label_options(p)
    return p


def structures(labels, values) -> list[dict]:
    """Per structure: value, name, voxels, volume (mL), surface area (mm^2, smoothed marching cubes)."""
    from volumen.surface import label_areas

    ml, counts, areas = labels.volumes_ml(), labels.counts(), label_areas(labels)
    return [{"value": v, "name": labels.names[v], "voxels": counts[v], "volume_ml": round(ml[v], 3),
             "area_mm2": round(areas[v], 1)} for v in values]


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
    facts["colour"] = "RGB" if volume.is_color else ""
    for key in ("series_uid", "series_description", "series_number", "n_files", "transfer_syntax", "sop_class",
                "photometric", "manufacturer", "modality_lut", "voi_lut", "display_inverted"):
        if key in meta:
            facts[key] = meta[key]
    return facts


_LABELS = {"series_uid": "series_uid", "n_files": "n_files", "transfer_syntax": "transfer", "sop_class": "SOP class",
           "photometric": "photometric", "modality_lut": "modality LUT", "voi_lut": "VOI LUT"}


def _series_listing(args) -> tuple[list, list[str]] | None:
    """The series of a DICOM folder and the skip notes; ``None`` for anything else."""
    from volumen.io import detect_format, list_series

    if str(args.input).startswith("phantom:") or not Path(args.input).is_dir() or detect_format(args.input) != "dicom":
        return None
    notes: list[str] = []
    return list_series(args.input, notes), notes


def _print_listing(path, series, notes) -> None:
    print(f"{len(series)} image series in {path}:")
    print(f"{'#':>5}  {'mod':<3} {'columns x rows x slices':<23} {'files':>11}  description  SeriesInstanceUID")
    for s in series:
        print(s.line())
    for n in notes:
        print(f"note:         {n}")


def run(args):
    listing = _series_listing(args)
    if listing is not None and len(listing[0]) > 1 and not args.series:
        series, notes = listing
        if args.json:
            print(json.dumps({"series": [asdict(s) for s in series], "notes": notes}, indent=2))
        else:
            _print_listing(args.input, series, notes)
            print("choose one with --series SERIES_INSTANCE_UID")
        return 0
    vol = load_from_args(args, quiet=True)  # its warnings are among the facts
    facts = describe(vol)
    labels = labels_from_args(args, vol)
    if labels is not None:
        facts["structures"] = structures(labels, shown_values(args, labels))
        facts["warnings"] += labels.meta["warnings"]
    if listing is not None:
        facts["series"] = [asdict(s) for s in listing[0]]
    if args.json:
        print(json.dumps(facts, indent=2))
        return 0
    if listing is not None:
        _print_listing(args.input, listing[0], [])  # skip notes are among the warnings below
        print()
    from volumen.core import mm_text, range_text

    z, y, x = facts["shape_zyx"]
    dz, dy, dx = facts["spacing_mm_zyx"]
    lines = [
        f"name:         {facts['name'] or '-'}",
        f"format:       {facts['format']}",
        f"size:         {x} x {y} x {z} voxels (x, y, z)",
        f"spacing:      {dx:g} x {dy:g} x {dz:g} mm (x, y, z)",
        f"extent:       {' x '.join(mm_text(v) for v in facts['extent_mm_xyz'])} mm",
        f"orientation:  {facts['orientation']}{' (oblique)' if facts['oblique'] else ''} "
        f"(voxel axes i, j, k toward these patient directions)",
        f"origin:       {', '.join(mm_text(v) for v in facts['origin_ras_mm'])} mm (RAS)",
        f"modality:     {facts['modality']}",
        f"values:       {range_text(*facts['value_range'], facts['units']).replace('..', ' .. ')} "
        f"{facts['units'] + ' ' if facts['units'] else ''}({facts['dtype']})",
    ]
    if facts["colour"]:
        lines.append(f"colour:       {facts['colour']} (channel last: data is z, y, x, 3)")
    for key, label in _LABELS.items():
        if facts.get(key):
            lines.append(f"{label + ':':14}{facts[key]}")
    if "structures" in facts:
        lines.append(f"structures:   {len(facts['structures'])} ({args.labels})")
        lines.append(f"  {'value':>5}  {'name':<24} {'voxels':>9} {'volume mL':>10} {'area mm^2':>10}")
        lines += [f"  {r['value']:>5}  {r['name']:<24} {r['voxels']:>9} {r['volume_ml']:>10.2f} {r['area_mm2']:>10.1f}"
                  for r in facts["structures"]]
    for w in facts["warnings"]:
        lines.append(f"warning:      {w}")
    print("\n".join(lines))
    return 0
