"""``volumen slices PATH -o DIR``: a PNG montage of the axial, coronal and sagittal planes."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._common import WINDOW_HELP, add_load_options, count, load_from_args, parse_point, parse_window
from ._label_tags import place_tags
from ._labels_opts import add_label_options, labels_from_args, shown_values

#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("out",)
#: default ``--size``: a small scan's planes (a 64-voxel MRI) are enlarged to be read on a screen
PANEL_SIZE = 512


def register(sub):
    p = sub.add_parser("slices", help="write a PNG montage of the three planes (and each plane)")
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    p.add_argument("-o", "--out", required=True, help="output folder (created if missing)")
    p.add_argument("--window", help=f"{WINDOW_HELP} (default: soft-tissue for a CT, else the display range)")
    p.add_argument("--size", type=count, default=PANEL_SIZE,
                   help=f"pixels along the longest side of the largest plane; the others keep its mm per pixel "
                        f"(default {PANEL_SIZE}; a larger scan is not shrunk; 0: one pixel per voxel)")
    p.add_argument("--at", help="world point X,Y,Z in RAS mm the planes pass through (default: centre)")
    add_load_options(p)
    add_label_options(p)
    return p


def _named_outlines(gray, lab, labels, values):
    """RGB PIL image: the slice with each structure's outline in its colour and its name inside it where there is
    room (``_label_tags.place_tags``: no name over another)."""
    from PIL import Image as PILImage
    from PIL import ImageDraw

    from volumen.core import outline_overlay

    img = PILImage.fromarray(outline_overlay(gray, lab, labels, values, fill=0.15))
    draw = ImageDraw.Draw(img)
    sizes = {}
    for v in values:
        x0, y0, x1, y1 = draw.textbbox((0, 0), labels.names[v], anchor="mm")
        sizes[int(v)] = (x1 - x0, y1 - y0)
    for v, centre, _ in place_tags(lab, values, sizes):
        draw.text(centre, labels.names[v], fill=(255, 255, 255), anchor="mm")
    return img


def write_label_montages(volume, labels, values, out: Path, stem: str, window=None, world=None,
                         size: int | None = None) -> list[Path]:
    """``stem_labels_<plane>.png`` for each plane and ``stem_labels_montage.png`` (side by side), outlines named,
    enlarged to ``size`` as :func:`write_montages` (the labels by nearest voxel, before the outlines are drawn)."""
    from PIL import Image as PILImage

    from volumen.core import PLANES, canonical, label_slice, slice_image

    can = canonical(volume)
    at = volume.center if world is None else world
    grays = [slice_image(volume, plane, world=at, window=window, canonical_volume=can) for plane in PLANES]
    zoom = zoom_for([g.shape for g in grays], size)
    images = []
    for plane, gray in zip(PLANES, grays, strict=True):
        lab = label_slice(labels, plane, world=at)[: gray.shape[0], : gray.shape[1]]
        images.append(_named_outlines(_resized(gray, zoom), _resized(lab, zoom, nearest=True), labels, values))
    strip = PILImage.new("RGB", (sum(i.width for i in images), max(i.height for i in images)))
    x = 0
    for i in images:
        strip.paste(i, (x, 0))
        x += i.width
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / f"{stem}_labels_montage.png"] + [out / f"{stem}_labels_{plane}.png" for plane in PLANES]
    for path, image in zip(paths, [strip, *images], strict=True):
        image.save(path)
    return paths


def zoom_for(shapes, size: int | None) -> float:
    """The one factor that brings the longest side of the planes (their ``shapes``) to ``size`` pixels; 1 when
    ``size`` is None or 0 or they are that large already (a large scan is not shrunk)."""
    longest = max(max(shape[:2]) for shape in shapes)
    return 1.0 if not size or longest >= size else size / longest


def _resized(picture: np.ndarray, zoom: float, nearest: bool = False) -> np.ndarray:
    """``picture`` scaled by ``zoom`` (bilinear, or nearest for labels); itself for a zoom of 1."""
    from PIL import Image as PILImage

    if zoom == 1.0:
        return picture
    rows, cols = (max(1, round(n * zoom)) for n in picture.shape[:2])
    how = PILImage.Resampling.NEAREST if nearest else PILImage.Resampling.BILINEAR
    if picture.dtype != np.uint8:  # label values: resized as 32-bit integers
        return np.asarray(PILImage.fromarray(picture.astype(np.int32)).resize((cols, rows), how)).astype(picture.dtype)
    return np.asarray(PILImage.fromarray(picture).resize((cols, rows), how))


def write_montages(volume, out: Path, stem: str, window=None, world=None, size: int | None = None) -> list[Path]:
    """Write ``stem_montage.png`` and one PNG per plane into ``out`` (enlarged to ``size``: :func:`zoom_for`);
    returns the paths. Every picture is drawn before the folder is made, so a point outside the volume leaves
    nothing behind."""
    from PIL import Image as PILImage

    from volumen.core import PLANES, canonical, montage, slice_image

    can = canonical(volume)
    at = volume.center if world is None else world
    pictures = {f"{stem}_montage.png": montage(volume, window=window, world=at)}
    for plane in PLANES:
        pictures[f"{stem}_{plane}.png"] = slice_image(volume, plane, world=at, window=window, canonical_volume=can)
    zoom = zoom_for([p.shape for name, p in pictures.items() if name != f"{stem}_montage.png"], size)
    pictures = {name: _resized(p, zoom) for name, p in pictures.items()}
    out.mkdir(parents=True, exist_ok=True)
    for name, picture in pictures.items():
        PILImage.fromarray(picture).save(out / name)
    return [out / name for name in pictures]


def run(args):
    vol = load_from_args(args)
    stem = Path(str(args.input).replace("phantom:", "")).name.split(".")[0] or "volume"
    window, at = parse_window(args.window, vol), parse_point(args.at)
    labels = labels_from_args(args, vol)
    paths = write_montages(vol, Path(args.out), stem, window=window, world=at, size=args.size)
    if labels is not None:
        paths += write_label_montages(vol, labels, shown_values(args, labels), Path(args.out), stem,
                                      window=window, world=at, size=args.size)
    for p in paths:
        print(p)
    return 0
