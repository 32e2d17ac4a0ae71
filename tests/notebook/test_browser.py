"""The viewer's page in headless Chromium (Debian's package, installed by `make test` where root and apt
are available): jupyter-rfb's front end must draw the widget's frame on a non-empty canvas."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest
from PIL import Image as PILImage

from volumen.core import Camera

#: flags for a browser without network, GPU or sandbox (containers), with nothing but the page to do
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--force-device-scale-factor=1", "--hide-scrollbars", "--virtual-time-budget=5000")


def _chromium() -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("Chromium is not installed (Debian package 'chromium'; `make test` installs it as root)")
    return exe


def test_the_exported_viewer_page_shows_the_frame_in_chromium(scene, tmp_path, output_dir):
    from volumen.notebook._widget import Viewer

    exe = _chromium()
    size = (96, 80)
    w = Viewer(scene, Camera.orbit(scene.volume, azimuth=-30), size, slices=False)
    try:
        page = tmp_path / "viewer.html"
        page.write_text(w.snapshot_html(), encoding="utf-8")
        frame = w.frame
    finally:
        w.close()
    shot = output_dir / "notebook_viewer_chromium.png"
    cmd = [exe, *CHROMIUM_FLAGS, f"--user-data-dir={tmp_path / 'profile'}", "--window-size=240,200",
           f"--screenshot={shot}", page.as_uri()]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and shot.exists(), proc.stderr[-2000:]
    got = np.asarray(PILImage.open(shot).convert("RGB")).astype(int)
    h, w_ = frame.shape[:2]
    # the widget draws a 1-px border inside its CSS box (border-box): the frame fills the (w-2, h-2) interior
    shown = got[1:h - 1, 1:w_ - 1]
    expected = np.asarray(PILImage.fromarray(frame).resize((w_ - 2, h - 2), PILImage.BILINEAR)).astype(int)
    inner = (slice(5, -5), slice(5, -5))  # and rounds its corners
    assert (shown[inner].max(axis=2) > 10).mean() > 0.05  # the canvas is not empty: the head covers part of it
    diff = np.abs(shown[inner] - expected[inner])
    assert diff.mean() < 1.0 and diff.max() <= 16  # it is the frame (the browser's resampling differs a little)
    assert (got[h + 2:, :] == 255).all() and (got[:, w_ + 2:] == 255).all()  # nothing else on the white page
