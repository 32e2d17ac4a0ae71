"""Seed files for the fuzzer: real files found on the machine and files volumen's writers produce.

A :class:`Seed` is a small folder held in memory: ``files`` maps a name to its bytes,
``main`` is the name handed to :func:`volumen.load` (``""`` for the folder itself) and
``options`` are the loader's keyword arguments (raw files need shape and dtype).
Seeds are grouped by *family*, the unit the campaign's table counts.

Real seeds: pydicom's installed test files, the shared VMTK aorta (MetaImage) and the
small MRIcron templates (NIfTI) when installed. Written seeds: a small oblique volume
saved by every writer, and the forms no writer produces (NRRD ASCII, detached NRRD and
MetaImage with a ``%d`` pattern or a LIST, VTK legacy ASCII and binary, raw).
"""

from __future__ import annotations

import io
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from volumen.data import shared_data

__all__ = ["Seed", "FAMILIES", "build_seeds"]

FAMILIES = ("nifti", "nrrd", "nhdr", "mha", "mhd", "vtk", "npy", "npz", "raw", "dicom")
_DICOM_MAX_BYTES = 100_000  # larger pydicom files slow the campaign without adding header variety
_TEMPLATES = ("JHU-WhiteMatter-labels-2mm.nii.gz", "AICHAmc.nii.gz")


@dataclass
class Seed:
    name: str
    family: str
    files: dict[str, bytes]
    main: str
    options: dict = field(default_factory=dict)


def _volume():
    from volumen.core import Volume

    data = (np.arange(5 * 6 * 7).reshape(5, 6, 7) * 37 % 1000 - 300).astype(np.int16)
    c, s = np.cos(0.3), np.sin(0.3)
    affine = np.array([[0.9 * c, -0.8 * s, 0, -20.0], [0.9 * s, 0.8 * c, 0, 15.0], [0, 0, 2.5, 7.0], [0, 0, 0, 1]])
    return Volume(data, spacing=(2.5, 0.8, 0.9), affine=affine, modality="CT", units="HU")


def _written() -> list[Seed]:
    """The small volume through every writer (read back from a temporary folder)."""
    from volumen.io import save

    vol = _volume()
    plan = [("nifti", "v.nii", {}), ("nifti", "v.nii.gz", {}), ("nifti", "v.hdr", {}),
            ("nrrd", "v.nrrd", {}), ("nrrd", "v.nrrd", {"encoding": "gzip"}), ("nhdr", "v.nhdr", {}),
            ("mha", "v.mha", {}), ("mha", "v.mha", {"compress": True}), ("mhd", "v.mhd", {}),
            ("mhd", "v.mhd", {"compress": True}), ("npy", "v.npy", {}), ("npz", "v.npz", {})]
    seeds = []
    for i, (family, name, opts) in enumerate(plan):
        with tempfile.TemporaryDirectory() as tmp:
            save(vol, Path(tmp) / name, **opts)
            files = {p.name: p.read_bytes() for p in Path(tmp).iterdir()}
        seeds.append(Seed(f"written-{i}-{name}", family, files, name))
    return seeds


def _handmade() -> list[Seed]:
    """Forms no volumen writer produces, written out here byte by byte."""
    vol = _volume()
    data = vol.data
    nz, ny, nx = data.shape
    le, be = data.astype("<i2").tobytes(), data.astype(">i2").tobytes()
    slices = {f"s{k:02d}.raw": data[k].astype("<i2").tobytes() for k in range(nz)}
    geo = "space: left-posterior-superior\nspace directions: (0.9,0,0) (0,0.8,0) (0,0,2.5)\nspace origin: (1,2,3)\n"
    nrrd_head = f"NRRD0004\ntype: short\ndimension: 3\nsizes: {nx} {ny} {nz}\n{geo}endian: little\n"
    mhd_head = (f"ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                f"TransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 1 2 3\nElementSpacing = 0.9 0.8 2.5\n"
                f"DimSize = {nx} {ny} {nz}\nElementType = MET_SHORT\n")
    ascii_values = "\n".join(" ".join(str(int(v)) for v in row) for row in data.reshape(-1, nx))
    vtk_head = (f"# vtk DataFile Version 3.0\nvolumen seed\n{{mode}}\nDATASET STRUCTURED_POINTS\n"
                f"DIMENSIONS {nx} {ny} {nz}\nSPACING 0.9 0.8 2.5\nORIGIN 1 2 3\nPOINT_DATA {data.size}\n"
                "SCALARS density short 1\nLOOKUP_TABLE default\n")
    return [
        Seed("nrrd-ascii", "nrrd", {"a.nrrd": (nrrd_head + "encoding: ascii\n\n" + ascii_values).encode()},
             "a.nrrd"),
        Seed("nhdr-pattern", "nhdr", {"p.nhdr": (nrrd_head + f"encoding: raw\ndata file: s%02d.raw 0 {nz - 1} 1 2\n"
                                                 ).encode(), **slices}, "p.nhdr"),
        Seed("nhdr-list", "nhdr", {"l.nhdr": (nrrd_head + "encoding: raw\ndata file: LIST 2\n"
                                              + "\n".join(slices) + "\n").encode(), **slices}, "l.nhdr"),
        Seed("mhd-pattern", "mhd", {"p.mhd": (mhd_head + f"ElementDataFile = s%02d.raw 0 {nz - 1} 1\n").encode(),
                                    **slices}, "p.mhd"),
        Seed("mhd-list", "mhd", {"l.mhd": (mhd_head + "ElementDataFile = LIST 2D\n" + "\n".join(slices)
                                           + "\n").encode(), **slices}, "l.mhd"),
        Seed("vtk-ascii", "vtk", {"a.vtk": (vtk_head.format(mode="ASCII") + ascii_values + "\n").encode()}, "a.vtk"),
        Seed("vtk-binary", "vtk", {"b.vtk": vtk_head.format(mode="BINARY").encode() + be}, "b.vtk"),
        Seed("raw-int16", "raw", {"v.raw": le}, "v.raw",
             {"shape": [nz, ny, nx], "dtype": "int16", "spacing": [2.5, 0.8, 0.9]}),
        Seed("raw-header", "raw", {"h.raw": b"HEAD" * 8 + be}, "h.raw",
             {"shape": [nz, ny, nx], "dtype": "int16", "byte_order": "big", "offset": 32}),
    ]


def _real() -> list[Seed]:
    seeds = []
    aorta = shared_data("vmtk-aorta", "aorta.mha")
    if aorta is not None:
        seeds.append(Seed("vmtk-aorta", "mha", {"aorta.mha": aorta.read_bytes()}, "aorta.mha"))
    templates = Path("/usr/share/mricron/templates")
    for name in _TEMPLATES:
        if (templates / name).is_file():
            seeds.append(Seed(f"mricron-{name}", "nifti", {name: (templates / name).read_bytes()}, name))
    try:
        import pydicom.data

        folder = Path(pydicom.data.__file__).parent / "test_files"
    except ImportError:
        return seeds
    for path in sorted(folder.glob("*.dcm")):
        if path.stat().st_size <= _DICOM_MAX_BYTES:
            seeds.append(Seed(f"pydicom-{path.name}", "dicom", {path.name: path.read_bytes()}, path.name))
    return seeds


def build_seeds(families=FAMILIES) -> dict[str, list[Seed]]:
    """Seeds by family (only the families asked for; every family has at least its written seeds)."""
    out: dict[str, list[Seed]] = {f: [] for f in families}
    for seed in _written() + _handmade() + _real():
        if seed.family in out:
            out[seed.family].append(seed)
    return out


def npy_bytes(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, array, allow_pickle=False)
    return buf.getvalue()
