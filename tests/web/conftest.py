"""Fixtures of the browser viewer's tests: its server on free local ports (stopped after), headless Chromium
(Debian's package; WebGL2 on SwiftShader), the iwer headset emulator (npm, `make web-deps`). Missing Chromium or
iwer: the tests that need them skip with the reason printed. Helpers: ``web_helpers.py``."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.web.web_helpers import AORTA_BUDGET_MB, ROOT, reference_scenes, start_server


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


