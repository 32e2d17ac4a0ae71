"""``volumen slices PATH -o DIR``: a PNG montage of the axial, coronal and sagittal planes."""

from __future__ import annotations

from pathlib import Path

from ._common import add_load_options, load_from_args, parse_point, parse_window


def register(sub):
    p = sub.add_parser("slices", help="write a PNG montage of the three planes (and each plane)")
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    p.add_argument("-o", "--out", required=True, help="output folder (created if missing)")
    p.add_argument("--window", help="bone, soft-tissue, lung, brain, or LEVEL,WIDTH in data units")
    p.add_argument("--at", help="world point X,Y,Z in RAS mm the planes pass through (default: centre)")
    add_load_options(p)
    return p


def write_montages(volume, out: Path, stem: str, window=None, world=None) -> list[Path]:
    """Write ``stem_montage.png`` and one PNG per plane into ``out``; returns the paths."""
    from PIL import Image as PILImage

    from volumen.core import PLANES, canonical, montage, slice_image

    out.mkdir(parents=True, exist_ok=True)
    can = canonical(volume)
    at = volume.center if world is None else world
    paths = [out / f"{stem}_montage.png"]
    PILImage.fromarray(montage(volume, window=window, world=at)).save(paths[0])
    for plane in PLANES:
        path = out / f"{stem}_{plane}.png"
        PILImage.fromarray(slice_image(volume, plane, world=at, window=window, canonical_volume=can)).save(path)
        paths.append(path)
    return paths


def run(args):
    vol = load_from_args(args)
    stem = Path(str(args.input).replace("phantom:", "")).name.split(".")[0] or "volume"
    paths = write_montages(vol, Path(args.out), stem, window=parse_window(args.window), world=parse_point(args.at))
    for p in paths:
        print(p)
    return 0
