"""Helpers of the browser viewer's tests: the reference scenes, the tolerances, showing a scene on the page and
reading it back, comparing pictures (a module of its own: every test folder has a ``conftest``)."""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
from tests.render import reference_scenes  # noqa: E402

#: the issue's bar, per picture: mean |RGBA diff|; and the 99th percentile (8-bit canvas: 1/255 rounding)
MEAN_TOL, P99_TOL = 0.01, 0.05
#: the displayed pictures (display values, 8 bits: the canvas over the view's black) against Image.to_uint8 of
#: the CPU's: mean and 99th percentile of |RGB diff|; and the page's metered exposure against the CPU's, stops
DISPLAY_MEAN_TOL, DISPLAY_P99_TOL, EXPOSURE_TOL = 2 / 255, 8 / 255, 0.02
#: the aorta as the page gets it in these tests: resampled to fit a 1 MiB texture budget (SwiftShader is slow)
AORTA_BUDGET_MB = 1.0

__all__ = ["reference_scenes", "MEAN_TOL", "P99_TOL", "DISPLAY_MEAN_TOL", "DISPLAY_P99_TOL", "EXPOSURE_TOL",
           "AORTA_BUDGET_MB", "start_server", "scene_json", "show", "capture", "picture", "compare", "displayed",
           "save_pair"]


def start_server(volume, scene, camera, **kw):
    from volumen.web import ViewerServer

    return ViewerServer(volume, scene.with_(volume=volume), camera, **kw).start()


def scene_json(scene) -> str:
    d = scene.to_dict()
    d["volume"] = ""
    return json.dumps(d)


def show(browser, scene, camera, size, linear: bool = False) -> dict:
    """Show ``scene`` / ``camera`` on the page at ``size`` and read the canvas back (see :func:`capture`)."""
    r = browser.evaluate(f"volumen.show({{scene: {scene_json(scene)}, camera: {camera.to_json()}, "
                         f"size: {list(size)}}})")
    assert r["error"] is None, r["error"]
    return capture(browser, linear)


def capture(browser, linear: bool = False) -> dict:
    """The canvas: {rgba float (h, w, 4) display values premultiplied (over black: what is shown), camera, scene,
    shown: {tonemap, exposure}}; ``linear``: also the picture before the display transform, float (h, w, 4)."""
    cap = browser.evaluate(f"volumen.capture({{linear: {str(linear).lower()}}})")
    cap["rgba"] = picture(cap["rgba"], cap["width"], cap["height"])
    if linear:
        lin = cap["linear"]
        cap["linear"] = np.frombuffer(base64.b64decode(lin["rgba"]), np.float32).reshape(
            lin["height"], lin["width"], 4)
    return cap


def picture(b64: str, w: int, h: int) -> np.ndarray:
    return np.frombuffer(base64.b64decode(b64), np.uint8).reshape(h, w, 4).astype(np.float32) / 255


def compare(got: np.ndarray, ref: np.ndarray, rgb_only: bool = False) -> tuple[float, float, float]:
    """``(mean, p99)`` of |RGBA diff| (RGB in an XR layer, which is opaque) and the fraction of pixels where one
    picture shows something (alpha > 0.02) and the other nothing."""
    if rgb_only:
        got, ref = got[..., :3], ref[..., :3]
        cover = np.mean((got.max(-1) > 0.02) != (ref.max(-1) > 0.02))
    else:
        cover = np.mean((got[..., 3] > 0.02) != (ref[..., 3] > 0.02))
    d = np.abs(got - ref)
    return float(d.mean()), float(np.percentile(d, 99)), float(cover)


def displayed(image, exposure: float | None = None) -> np.ndarray:
    """What the CPU's ``image`` shows (``Image.to_uint8`` over black), float RGB (h, w, 3) in [0, 1]; ``exposure``
    (stops) replaces a metered one (an XR eye shown with the other's meter)."""
    from volumen.core import Display

    disp = image.display or Display(tonemap="linear")
    if exposure is not None:
        disp = Display(tonemap=disp.tonemap, exposure=exposure)
    return image.to_uint8(display=disp).astype(np.float32) / 255


def save_pair(path: Path, got: np.ndarray, ref: np.ndarray) -> None:
    from PIL import Image as PILImage

    both = np.clip(np.hstack([got[..., :3], ref[..., :3]]), 0, 1)
    PILImage.fromarray((both * 255 + 0.5).astype(np.uint8)).save(path)
