"""``volumen bench web``: frames per second of the browser viewer in headless Chromium, desktop and both eyes,
beside the OpenGL device on the same kind of renderer.

The page runs in Debian's Chromium on SwiftShader (a software WebGL2: this machine has no GPU) and draws
each case with the frame packed once (what a moved camera costs): the median of pictures drawn back to back,
each finished before the next (a pixel read back). VR: an ``immersive-vr`` session of the iwer headset
emulator (both eyes side by side, the governor off), the median time to draw both eyes of a frame. Beside
them: the ``gl`` device (``render(device="gl")``) on Mesa's llvmpipe, the other software renderer, for the
desktop picture and for two eye-sized pictures: its whole frame (packing, upload, draw, float read-back) and
its draw and read-back alone (``Image.stats`` timings, ``kernel``). Each page picture (its linear picture, before
the display pass, which the timings include) is checked against the CPU's (mean |RGBA diff|) so a fast wrong
picture cannot pass unseen.
"""

from __future__ import annotations

import base64
import json
import os
import time
from pathlib import Path

import numpy as np

__all__ = ["bench_web", "WEB_CASES", "WEB_DATASETS", "WEB_QUICK", "iwer_script"]

#: (mode, shading, preset)
WEB_CASES = [("composite", "headlight", "ct-bone"), ("composite", "shadows", "ct-bone"), ("mip", "none", None),
             ("isosurface", "headlight", None)]
WEB_DATASETS = {"head-phantom-128": ("head", (128, 128, 128)), "aorta-157x393x34": ("aorta", None)}
WEB_QUICK = {"datasets": {"head-phantom-32": ("head", (32, 32, 32))}, "size": (48, 48), "eye": (32, 32),
             "frames": 2, "cases": [("composite", "headlight", "ct-bone"), ("mip", "none", None)]}


def iwer_script() -> str | None:
    """The iwer emulator installed for a stereo Meta Quest 3 (``$VOLUMEN_IWER``, or ``.web-deps`` of the
    current folder or of the source checkout: ``make web-deps``); None where it is not installed."""
    here = Path(__file__).resolve().parents[2]
    for p in (os.environ.get("VOLUMEN_IWER"), Path.cwd() / ".web-deps/node_modules/iwer/build/iwer.min.js",
              here / ".web-deps/node_modules/iwer/build/iwer.min.js"):
        if p and Path(p).exists():
            return (Path(p).read_text(encoding="utf-8") + "\n;window.iwerDevice = new IWER.XRDevice(IWER.metaQuest3);"
                    "iwerDevice.stereoEnabled = true; iwerDevice.installRuntime({forceInstall: true});")
    return None


def _dataset(kind, shape):
    from volumen.bench._render import load_dataset

    if kind == "aorta":  # the aorta read as stored, the presets moved +1000 onto its units
        from volumen.data import shared_data
        from volumen.io import load

        path = shared_data("vmtk-aorta", "aorta.mha")
        return None if path is None else (load(path), 1000.0)
    return load_dataset(kind, shape)


def _scene(volume, mode, shading, preset, offset):
    from volumen.core import Isosurface, Light, Scene, Shading, TransferFunction
    from volumen.render import default_transfer

    if preset:
        tf = TransferFunction.preset(preset).shifted(offset or 0.0)
    else:
        tf = default_transfer(volume, mode)
    c, d = np.asarray(volume.center), volume.diagonal
    lights = (Light(position=tuple(c + d * np.array([0.6, -0.8, 0.7])), intensity=1.0),)
    return Scene(volume=volume, transfer=tf, mode=mode, shading=Shading(mode=shading), lights=lights,
                 isosurface=Isosurface(value=300.0 + (offset or 0.0)))


def _gl_times(scene, camera, size, frames):
    from volumen.render import render

    render(scene, camera, size, device="gl")   # shader compiled, volume uploaded
    total, kernel = [], []
    for _ in range(frames):
        t = time.perf_counter()
        image = render(scene, camera, size, device="gl")
        total.append(time.perf_counter() - t)
        kernel.append(image.stats["timings"]["kernel"])
    return 1e3 * float(np.median(total)), 1e3 * float(np.median(kernel))


def _page_case(b, scene, camera, size, frames):
    from volumen.render import render

    d = scene.to_dict()
    d["volume"] = ""
    b.evaluate(f"volumen.show({{scene: {json.dumps(d)}, camera: {camera.to_json()}, size: {list(size)}}})")
    cap = b.evaluate("volumen.capture({linear: true})")   # the picture before the display transform
    got = np.frombuffer(base64.b64decode(cap["linear"]["rgba"]), np.float32).reshape(size[1], size[0], 4)
    diff = float(np.abs(got - render(scene, camera, size, device="cpu").rgba).mean())
    return b.evaluate(f"volumen.timeFrames({frames})"), diff


def bench_web(*, datasets=None, size=(256, 256), eye=(256, 256), cases=None, frames: int = 5,
              progress=print):
    """Run the benchmark; returns the :class:`~volumen.bench.Table`."""
    from volumen.bench import Table
    from volumen.core import Camera
    from volumen.render.raster import context_info

    from ._browser import Chromium
    from ._server import ViewerServer

    info = context_info()
    iwer = iwer_script()
    browser = "Chromium"
    table = Table(f"volumen bench web (the page in headless Chromium on SwiftShader; the gl device on "
                  f"{info['GL_RENDERER']})", [
        ("dataset", "data set", "s"), ("mode", "mode", "s"), ("shading", "shading", "s"),
        ("page_ms", f"page ms {size[0]}x{size[1]}", ".1f"), ("page_fps", "page fps", ".1f"),
        ("vr_ms", f"VR ms 2 x {eye[0]}x{eye[1]}", ".1f"), ("vr_fps", "VR fps", ".1f"),
        ("gl_ms", "gl ms (frame)", ".1f"), ("gl_kernel_ms", "gl ms (draw)", ".1f"),
        ("gl_eyes_ms", "gl ms 2 eyes (draw)", ".1f"), ("diff", "page vs cpu |diff|", ".4f")])
    for dname, (kind, shape) in (datasets or WEB_DATASETS).items():
        data = _dataset(kind, shape)
        if data is None:
            table.notes.append(f"{dname}: not on this machine")
            continue
        vol, offset = data
        camera = Camera.orbit(vol, azimuth=-30, elevation=15)
        scenes = [(case, _scene(vol, *case, offset)) for case in cases or WEB_CASES]
        rows = {}
        with ViewerServer(vol, scenes[0][1], camera) as server, Chromium((2 * eye[0], eye[1])) as b:
            if iwer:
                b.add_script(iwer)
            b.set_size(2 * eye[0], eye[1])
            b.open(server.url)
            browser = b.version()
            served = server.handlers.served().volume
            for (mode, shading, _), scene in scenes:
                scene = scene.with_(volume=served)
                ms, diff = _page_case(b, scene, camera, size, frames)
                gl_ms, gl_kernel = _gl_times(scene, camera, size, frames)
                _, gl_eye = _gl_times(scene, camera, eye, frames)
                rows[mode, shading] = table.add(dataset=dname, mode=mode, shading=shading, page_ms=ms,
                                                page_fps=1e3 / ms, gl_ms=gl_ms, gl_kernel_ms=gl_kernel,
                                                gl_eyes_ms=2 * gl_eye, diff=diff)
                progress(f"  {dname} {mode}/{shading}: page {ms:.1f} ms, gl {gl_ms:.1f} ms (draw {gl_kernel:.1f})")
            if iwer:
                b.evaluate("volumen.enterVR({governor: false})")
                for (mode, shading, _), scene in scenes:
                    d = scene.to_dict()
                    d["volume"] = ""
                    b.evaluate(f"volumen.sceneVR({json.dumps(d)})")
                    ms = b.evaluate(f"volumen.timeFramesVR({frames})")
                    rows[mode, shading].update(vr_ms=ms, vr_fps=1e3 / ms)
                    progress(f"  {dname} {mode}/{shading}: VR both eyes {ms:.1f} ms")
    table.notes.append(f"page: {browser} WebGL2 on SwiftShader; gl: {info['GL_RENDERER']}, {info['GL_VERSION']}; "
                       f"both software renderers on this machine's {os.cpu_count()} cores, load "
                       f"{os.getloadavg()[0]:.1f} at the end")
    table.notes.append("page ms and VR ms: medians of pictures drawn from an already packed frame, each finished "
                       "before the next; gl ms (frame): the whole render() (packing, upload, draw, float read-back); "
                       "gl ms (draw): its draw and read-back")
    if not iwer:
        table.notes.append("iwer not installed (`make web-deps`): no VR column")
    return table
