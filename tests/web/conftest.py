"""Fixtures of the browser viewer's tests: its server on free local ports (stopped after), headless Chromium
(Debian's package; WebGL2 on SwiftShader), the iwer headset emulator (npm, `make web-deps`), and the
comparison of the page's picture with the CPU's. Missing Chromium or iwer: the tests that need them skip with
the reason printed."""

from __future__ import annotations

import base64
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "render"))  # the reference scenes of the ray caster's tests
import reference_scenes  # noqa: E402

#: the issue's bar, per picture: mean |RGBA diff|; and the 99th percentile (8-bit canvas: 1/255 rounding)
MEAN_TOL, P99_TOL = 0.01, 0.05
#: the aorta as the page gets it in these tests: resampled to fit a 1 MiB texture budget (SwiftShader is slow)
AORTA_BUDGET_MB = 1.0


def iwer_path() -> Path:
    return Path(os.environ.get("VOLUMEN_IWER", ROOT / ".web-deps/node_modules/iwer/build/iwer.min.js"))


def skip(reason: str):
    print(f"skipped: {reason}")
    pytest.skip(reason)


@pytest.fixture(scope="session")
def chromium():
    from volumen.web import BrowserUnavailable, find_chromium

    try:
        return find_chromium()
    except BrowserUnavailable as exc:
        skip(str(exc))


@pytest.fixture(scope="session")
def iwer_source():
    p = iwer_path()
    if not p.exists():
        skip(f"the WebXR emulator iwer is not installed ({p} is missing: `make web-deps` installs it from npm)")
    return p.read_text(encoding="utf-8")


def start_server(volume, scene, camera, **kw):
    from volumen.web import ViewerServer

    return ViewerServer(volume, scene.with_(volume=volume), camera, **kw).start()


@pytest.fixture(scope="module")
def head_server():
    vol, tf, iso, zoom = reference_scenes.volumes()["head"]
    scene, cam, _ = reference_scenes.scenes()["head/composite/headlight"]
    srv = start_server(vol, scene, cam)
    yield srv
    srv.stop()


@pytest.fixture(scope="module")
def aorta_server():
    if "aorta" not in reference_scenes.volumes():
        skip(f"{reference_scenes.AORTA} is not on this machine")
    vol = reference_scenes.volumes()["aorta"][0]
    scene, cam, _ = reference_scenes.scenes()["aorta/composite/headlight"]
    srv = start_server(vol, scene, cam, budget_mb=AORTA_BUDGET_MB)
    yield srv
    srv.stop()


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
