"""``volumen demo``: the main job on the built-in phantoms; writes pictures and a gallery into ``out/``.

The gallery (``out/gallery/index.html``) shows each phantom in every ray-casting
mode and shading model with a caption naming the settings; each picture has its
``--save-settings`` JSON beside it, so ``volumen render --settings X.json -o X.png``
reproduces it bit for bit.
"""

from __future__ import annotations

import html
import json
import time
from pathlib import Path

from ._slices import write_montages

DEMO_WINDOWS = {"head": "brain", "torso": "soft-tissue"}
GALLERY_SIZE = (256, 256)


#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("out",)


def register(sub):
    p = sub.add_parser("demo", help="render the built-in phantoms (slices and a 3-D gallery) into a folder")
    p.add_argument("--out", default="out", help="output folder (default: out)")
    p.add_argument("--size", type=int, default=GALLERY_SIZE[0], help="gallery picture size in pixels (square)")
    return p


def gallery_entries(name: str, volume) -> list[tuple[str, dict, str]]:
    """``(file stem, scene settings, caption)`` for one phantom: every mode and shading model."""
    c = volume.center
    d = volume.diagonal
    lights = [{"position": [c[0] + d, c[1] + d, c[2] + d * 0.8], "direction": [-1, -1, -0.8], "exponent": 4.0,
               "intensity": 1.0, "color": [1.0, 0.95, 0.85]},
              {"position": [c[0] - d, c[1] + d * 0.5, c[2]], "direction": [1, -0.5, 0], "exponent": 0.0,
               "intensity": 0.4, "color": [0.6, 0.7, 1.0]}]
    tissue = "ct-skin-bone" if name == "head" else "ct-vessels"
    entries = [
        ("composite_bone_none", dict(mode="composite", preset="ct-bone", shading="none"),
         "composite (DVR), ct-bone, emission-absorption only"),
        ("composite_bone_headlight", dict(mode="composite", preset="ct-bone", shading="headlight"),
         "composite, ct-bone, Phong with a headlight"),
        (f"composite_{tissue}_phong", dict(mode="composite", preset=tissue, shading="phong", lights=lights),
         f"composite, {tissue}, Phong with a warm spot light (upper right) and a blue fill light"),
        ("composite_soft_headlight", dict(mode="composite", preset="ct-soft-tissue", shading="headlight"),
         "composite, ct-soft-tissue, headlight"),
        ("mip", dict(mode="mip", shading="none"), "maximum intensity projection"),
        ("minip", dict(mode="minip", shading="none", slab=True),
         "minimum intensity projection of a slab inside the body (the middle half in x and y), "
         "window -1000..100 HU: air-filled airways, sinuses and colon"),
        ("average", dict(mode="average", shading="none"), "average intensity projection"),
        ("iso300_headlight", dict(mode="isosurface", iso=300.0, shading="headlight"),
         "isosurface at 300 HU (bone), headlight"),
        ("iso-500_phong", dict(mode="isosurface", iso=-500.0, shading="phong", lights=lights),
         "isosurface at -500 HU (skin/air), two lights"),
    ]
    return entries


ORBIT = {"view": "anterior", "azimuth": -25, "elevation": 10, "zoom": 1.5}


def gallery_scenes(phantoms: dict):
    """``(phantom name, file stem, caption, scene, camera)`` of every gallery picture."""
    from dataclasses import replace

    from volumen.core import Camera, Clipping, Isosurface, Light, Scene, Shading, TransferFunction
    from volumen.render import default_transfer

    for name, volume in phantoms.items():
        camera = Camera.orbit(volume, **ORBIT)
        for stem, s, caption in gallery_entries(name, volume):
            mode = s["mode"]
            tf = TransferFunction.preset(s["preset"]) if "preset" in s else default_transfer(volume, mode)
            scene = Scene(volume=volume, volume_ref=f"phantom:{name}", transfer=tf, mode=mode,
                          shading=Shading(mode=s["shading"]),
                          lights=tuple(Light(**lt) for lt in s.get("lights", ())))
            if mode == "isosurface":
                scene = replace(scene, isosurface=Isosurface(value=s["iso"]))
            if s.get("slab"):
                nz, ny, nx = volume.shape
                crop = (nx * 0.25, nx * 0.75, ny * 0.25, ny * 0.75, 0, nz - 1)
                scene = replace(scene, clipping=Clipping(crop=crop),
                                transfer=TransferFunction.window_level(1100.0, -450.0, opacity=(1.0, 1.0)))
            yield name, stem, caption, scene, camera


def render_gallery(out: Path, phantoms: dict, size: int, progress=print) -> Path:
    """Render :func:`gallery_scenes` into ``out``; write ``index.html``; return its path."""
    from volumen.render import Technique, render

    from ._render import SETTINGS_VERSION

    out.mkdir(parents=True, exist_ok=True)
    cards = []
    for name, stem, caption, scene, camera in gallery_scenes(phantoms):
        t0 = time.perf_counter()
        image = render(scene, camera, (size, size))
        ms = (time.perf_counter() - t0) * 1e3
        png = out / f"{name}_{stem}.png"
        image.save(png)
        settings = {"version": SETTINGS_VERSION, "scene": scene.to_dict(), "camera": camera.to_dict(),
                    "size": [size, size], "background": [0, 0, 0], "orbit": dict(ORBIT), "load": {},
                    "device": image.stats["renderer"]["device"], "technique": Technique().to_dict()}
        png.with_suffix(".json").write_text(json.dumps(settings, indent=2))
        cards.append((name, png.name, caption, ms, png.with_suffix(".json").name))
        progress(f"  {png.name}: {ms:.0f} ms")
    body = "\n".join(
        f'<figure><img src="{html.escape(f)}" width="{size}" height="{size}" alt="{html.escape(c)}">'
        f"<figcaption><b>{html.escape(n)}</b>: {html.escape(c)}<br><small>{ms:.0f} ms on the CPU; "
        f'<a href="{html.escape(j)}">settings</a></small></figcaption></figure>'
        for n, f, c, ms, j in cards)
    index = out / "index.html"
    index.write_text(
        "<!doctype html><html><head><meta charset='utf-8'><title>volumen gallery</title><style>"
        "body{font-family:sans-serif;background:#111;color:#ddd}figure{display:inline-block;margin:8px;"
        f"width:{size}px;vertical-align:top}}figcaption{{font-size:13px}}a{{color:#9cf}}</style></head><body>"
        "<h1>volumen: built-in phantoms, anterior-left view</h1><p>Each picture reproduces with "
        "<code>volumen render --settings NAME.json -o NAME.png</code>.</p>" + body + "</body></html>")
    return index


def warm_gallery(phantoms: dict, progress=print) -> dict:
    """Compile (or load from the cache) the gallery's kernels in one process per core (``volumen.render.warm``)."""
    from volumen.render import warm
    from volumen.render._warm import cores

    jobs = [(scene, camera) for _, _, _, scene, camera in gallery_scenes(phantoms)]
    t0 = time.perf_counter()
    progress(f"compiling the gallery's kernels for this machine, {cores()} at a time (loaded from the cache after "
             "the first run)...")
    done = warm(jobs, progress=progress, here=True)
    progress(f"kernels ready in {time.perf_counter() - t0:.1f} s")
    return done


def run(args):
    from volumen.data import phantom

    out = Path(args.out)
    written: list[Path] = []
    phantoms = {}
    for name, window in DEMO_WINDOWS.items():
        t0 = time.perf_counter()
        vol = phantom(name)
        phantoms[name] = vol
        print(f"phantom {name}: {vol.shape[2]} x {vol.shape[1]} x {vol.shape[0]} voxels "
              f"in {time.perf_counter() - t0:.2f} s")
        written += write_montages(vol, out / "slices", name, window=window)
        written += write_montages(vol, out / "slices", f"{name}_bone", window="bone")[:1]
    print(f"wrote {len(written)} slice pictures into {(out / 'slices').resolve()}")
    warm_gallery(phantoms)
    print("rendering the gallery...")
    index = render_gallery(out / "gallery", phantoms, args.size)
    print(f"gallery: {index.resolve()}")
    return 0
