"""``volumen bench labels``: the cost of label-aware compositing against plain compositing on the same scene.

The organ phantom (int16 HU, labels on its grid), ``ct-soft-tissue``, anterior orbit, at two sizes; per
shading model (none, headlight) the plain composite frame, the same with every structure solid at
opacity 0.8 over the scan's preset, and textured (the scan's opacity tinted by each structure). Frame
times are medians after a warm-up frame (which compiles the kernels); the ratio is label / plain.
"""

from __future__ import annotations

from ._table import Table, median_time, resolve_device

__all__ = ["bench_labels"]

FULL = {"sizes": (128, 256), "image": (512, 512)}
QUICK = {"sizes": (48,), "image": (96, 96)}


def bench_labels(quick: bool = False, repeat: int = 3, device: str = "cpu") -> Table:
    """Time plain and label-aware composite frames; returns the table (ms and ratios)."""
    from volumen.core import Camera, LabelLayer, Scene, Shading, TransferFunction
    from volumen.data import organ_phantom
    from volumen.render import render

    dev, dev_name = resolve_device(device)
    cfg = QUICK if quick else FULL
    table = Table(f"Label-aware composite vs plain composite ({dev_name})",
                  [("volume", "volume", ""), ("shading", "shading", ""), ("plain_ms", "plain ms", ".1f"),
                   ("solid_ms", "labels solid ms", ".1f"), ("solid_ratio", "solid / plain", ".2f"),
                   ("textured_ms", "labels textured ms", ".1f"), ("textured_ratio", "textured / plain", ".2f")])
    for n in cfg["sizes"]:
        vol, labels = organ_phantom(n, spacing=256.0 / n)
        tf = TransferFunction.preset("ct-soft-tissue", value_range=vol.value_range())
        cam = Camera.orbit(vol, view="anterior", azimuth=25.0, elevation=15.0)
        for shading in ("none", "headlight"):
            plain = Scene(volume=vol, transfer=tf, shading=Shading(mode=shading))
            solid = plain.with_(labels=LabelLayer(labels, opacity=0.8))
            textured = plain.with_(labels=LabelLayer(labels, textured=True))
            ms = {k: 1000 * median_time(lambda s=s, c=cam: render(s, c, cfg["image"], device=dev), repeat)
                  for k, s in (("plain", plain), ("solid", solid), ("textured", textured))}
            table.add(volume=f"{n}^3", shading=shading, plain_ms=ms["plain"], solid_ms=ms["solid"],
                      solid_ratio=ms["solid"] / ms["plain"], textured_ms=ms["textured"],
                      textured_ratio=ms["textured"] / ms["plain"])
    table.notes.append(f"image {cfg['image'][0]}x{cfg['image'][1]}, median of {repeat} frames after a warm-up")
    return table
