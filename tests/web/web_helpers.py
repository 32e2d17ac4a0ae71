"""Helpers of the browser viewer's tests: the reference scenes, the tolerances, showing a scene on the page and
reading it back, comparing pictures (a module of its own: every test folder has a ``conftest``)."""

from __future__ import annotations

import base64
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "render"))  # the reference scenes of the ray caster's tests
import reference_scenes  # noqa: E402

#: the issue's bar, per picture: mean |RGBA diff|; and the 99th percentile (8-bit canvas: 1/255 rounding)
MEAN_TOL, P99_TOL = 0.01, 0.05
#: the aorta as the page gets it in these tests: resampled to fit a 1 MiB texture budget (SwiftShader is slow)
AORTA_BUDGET_MB = 1.0

__all__ = ["reference_scenes", "MEAN_TOL", "P99_TOL", "AORTA_BUDGET_MB", "start_server", "scene_json", "show",
           "capture", "picture", "compare", "save_pair"]


def start_server(volume, scene, camera, **kw):
    from volumen.web import ViewerServer

    return ViewerServer(volume, scene.with_(volume=volume), camera, **kw).start()


def scene_json(scene) -> str:
    d = scene.to_dict()
    d["volume"] = ""
    return json.dumps(d)


def show(browser, scene, camera, size) -> dict:
    """Show ``scene`` / ``camera`` on the page at ``size`` and read the canvas back: {rgba float (h, w, 4), camera}."""
    r = browser.evaluate(f"volumen.show({{scene: {scene_json(scene)}, camera: {camera.to_json()}, "
                         f"size: {list(size)}}})")
    assert r["error"] is None, r["error"]
    return capture(browser)


def capture(browser) -> dict:
    cap = browser.evaluate("volumen.capture()")
    cap["rgba"] = picture(cap["rgba"], cap["width"], cap["height"])
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


def save_pair(path: Path, got: np.ndarray, ref: np.ndarray) -> None:
    from PIL import Image as PILImage

    both = np.clip(np.hstack([got[..., :3], ref[..., :3]]), 0, 1)
    PILImage.fromarray((both * 255 + 0.5).astype(np.uint8)).save(path)
