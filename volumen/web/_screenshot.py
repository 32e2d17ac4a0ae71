"""``volumen serve --screenshot``: the page (or the two eyes of an emulated headset) saved as PNG by headless
Chromium, as ``volumen view --screenshot`` saves the application's window."""

from __future__ import annotations

import base64
from pathlib import Path

import numpy as np

__all__ = ["screenshot"]


def screenshot(server, path, window=(1280, 800), vr: bool = False) -> Path:
    """Open ``server``'s page in a ``window = (width, height)`` CSS-pixel window, wait for the picture and the
    slice views, and save the window to ``path``; ``vr``: enter an immersive-vr session of the iwer emulator
    first (both eyes side by side fill the window). Raises ``BrowserUnavailable`` / ``ValueError`` when
    Chromium or (for ``vr``) iwer is missing."""
    from ._bench import iwer_script
    from ._browser import Chromium

    w, h = window
    with Chromium(window) as b:
        if vr:
            script = iwer_script()
            if script is None:
                raise ValueError("the two-eye screenshot needs the WebXR emulator iwer (`make web-deps`)")
            b.add_script(script)
        b.set_size(w, h)
        b.open(server.url)
        b.evaluate("volumen.shown()")
        if vr:   # the emulated head steps up to the table and looks down at the volume
            b.evaluate("volumen.enterVR({governor: false}).then(() => { iwerDevice.position.set(0, 1.47, -0.27); "
                       f"iwerDevice.quaternion.set({np.sin(np.radians(-12)):.6f}, 0, 0, {np.cos(np.radians(-12)):.6f});"
                       " return volumen.framesVR(3); })")
        png = base64.b64decode(b.call("Page.captureScreenshot", format="png")["data"])
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(png)
    return out
