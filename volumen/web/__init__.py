"""The browser viewer (``volumen serve``): a web server and its page, a WebGL2 ray caster with WebXR.

The page draws with the desktop OpenGL ray caster's shader files (``render/raster/shaders``, compiled as
GLSL ES 3.00) from frames packed by the same Python code (``raycast.pack_frame``), so it shows the CPU's
picture; in an ``immersive-vr`` session each eye is ray cast with its own pose and projection.

* :class:`ViewerServer`: the server of one scan (token, loopback by default, fixed routes), held to
  :class:`ServeLimits` (connections, deadlines, workers, memory per frame);
* :class:`ServedVolume`: the scan fitted to the client's 3-D texture size and memory budget, as 16 bits;
* :func:`web_frame`, :func:`encode`, :func:`decode`: the frames the page draws and their binary layout;
* :class:`Chromium`: headless Chromium driven over the DevTools protocol (tests, ``volumen bench web``).

Layer: beside ``app`` and ``notebook``; it imports the renderers' packing code and nothing imports it
(docs/design.md section 10).
"""

from ._browser import BrowserUnavailable, Chromium, find_chromium
from ._certificate import certificate_names
from ._frames import decode, encode, web_frame
from ._serve_limits import ServeLimits
from ._served import ServedVolume
from ._server import ViewerServer, is_loopback, new_token

__all__ = ["ViewerServer", "ServeLimits", "ServedVolume", "web_frame", "encode", "decode", "Chromium",
           "BrowserUnavailable", "find_chromium", "is_loopback", "new_token", "certificate_names"]
