"""``volumen demo``: the main job on the built-in phantoms; writes pictures into ``out/``."""

from __future__ import annotations

import time
from pathlib import Path

from ._slices import write_montages

DEMO_WINDOWS = {"head": "brain", "torso": "soft-tissue"}


def register(sub):
    p = sub.add_parser("demo", help="render the built-in phantoms into a folder")
    p.add_argument("--out", default="out", help="output folder (default: out)")
    return p


def run(args):
    from volumen.data import phantom

    out = Path(args.out)
    written: list[Path] = []
    for name, window in DEMO_WINDOWS.items():
        t0 = time.perf_counter()
        vol = phantom(name)
        print(f"phantom {name}: {vol.shape[2]} x {vol.shape[1]} x {vol.shape[0]} voxels "
              f"in {time.perf_counter() - t0:.2f} s")
        written += write_montages(vol, out / "slices", name, window=window)
        written += write_montages(vol, out / "slices", f"{name}_bone", window="bone")[:1]
    print(f"wrote {len(written)} pictures into {out.resolve()}:")
    for p in written:
        print(f"  {p}")
    return 0
