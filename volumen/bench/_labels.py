"""``volumen bench labels``: the cost of label-aware compositing against plain compositing on the same scene.

The organ phantom (int16 HU, labels on its grid), ``ct-soft-tissue``, anterior orbit, at two sizes; per
shading model (none, headlight) the plain composite frame, the same with every structure solid at
opacity 0.8 over the scan's preset, and textured (the scan's opacity tinted by each structure). After a
warm-up frame of each (which compiles the kernels), rounds alternate the three frames, so a machine shared
with other work slows them alike; times are medians over the rounds, the ratios medians of each round's
label / plain.
"""

from __future__ import annotations

import time

import numpy as np

from ._table import Table, resolve_device

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
            t = _alternate({"plain": plain, "solid": solid, "textured": textured},
                           lambda s, c=cam: render(s, c, cfg["image"], device=dev), repeat)
            table.add(volume=f"{n}^3", shading=shading, plain_ms=1000 * np.median(t["plain"]),
                      solid_ms=1000 * np.median(t["solid"]), solid_ratio=np.median(t["solid"] / t["plain"]),
                      textured_ms=1000 * np.median(t["textured"]),
                      textured_ratio=np.median(t["textured"] / t["plain"]))
    table.notes.append(f"image {cfg['image'][0]}x{cfg['image'][1]}, {repeat} alternating rounds after a warm-up; "
                       "ratios: median of the rounds' ratios")
    return table


def _alternate(scenes: dict, frame, rounds: int) -> dict:
    """Seconds per frame of each scene (arrays of ``rounds``), one frame of each per round after a warm-up."""
    for sc in scenes.values():
        frame(sc)
    times = {k: [] for k in scenes}
    for _ in range(max(int(rounds), 1)):
        for k, sc in scenes.items():
            t0 = time.perf_counter()
            frame(sc)
            times[k].append(time.perf_counter() - t0)
    return {k: np.asarray(v) for k, v in times.items()}
