"""The viewer's web server (aiohttp): one page, its modules and shaders, and the data of one opened scan.

Privacy and access (the scan is a patient's):

* it binds ``127.0.0.1`` unless told otherwise (``volumen serve --host`` warns in one line when the host is
  not a loopback address);
* every request needs the access token, a random 128-bit number printed once in the URL: in the query
  (``?token=``, the URL's), an ``X-Volumen-Token`` header, or the cookie the first answer sets (``HttpOnly``,
  ``SameSite=Strict``; the page's module imports carry it). Compared in constant time; without it every
  route answers 403;
* routes are a fixed table (:data:`ROUTES`, the static files of the package read into memory at start): no
  part of a request reaches the file system, and anything not in the table (``..``, encoded ``..``,
  absolute paths) answers 404;
* nothing served or logged names the patient: the volume's geometry, modality, units and values only
  (``ServedVolume.info``), never its name, source path or DICOM fields; log lines hold the method, the
  route, the status and the time, never the query (the token) or a path the client sent.
"""

from __future__ import annotations

import asyncio
import hmac
import ipaddress
import json
import logging
import secrets
import socket
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from importlib import resources

import numpy as np
from aiohttp import web

from ._served import DEFAULT_BUDGET_MB, DEFAULT_MAX_3D, ServedVolume

__all__ = ["ViewerServer", "new_token", "is_loopback", "ROUTES", "STATIC_FILES", "log"]

log = logging.getLogger("volumen.web")

#: the page's files (package data under ``volumen/web/static``), served at ``/`` and ``/static/NAME``
STATIC_FILES = ("index.html", "style.css", "main.js", "api.js", "gl.js", "program.js", "camera.js", "linalg.js",
                "xr.js", "ui.js", "overlay.js", "slices.js", "viewer.js", "display.js")
_TYPES = {".html": "text/html", ".css": "text/css", ".js": "text/javascript"}
#: route -> (method, handler name of :class:`_Handlers`)
ROUTES = {"": ("GET", "index"), "info.json": ("GET", "info"), "shaders.json": ("GET", "shaders"),
          "volume.bin": ("GET", "volume"), "frame.bin": ("POST", "frame"), "slice.png": ("GET", "slice"),
          **{f"static/{name}": ("GET", "static") for name in STATIC_FILES}}
_MAX_BODY = 1 << 20


def new_token() -> str:
    """A random 128-bit access token (32 hex digits)."""
    return secrets.token_hex(16)


def is_loopback(host: str) -> bool:
    """Whether ``host`` (a name or an address) is this machine's loopback only."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _static() -> dict[str, tuple[bytes, str]]:
    root = resources.files(__package__).joinpath("static")
    out = {}
    for name in STATIC_FILES:
        data = root.joinpath(name).read_bytes()
        out[name] = (data, _TYPES["." + name.rsplit(".", 1)[1]])
    return out


class _Handlers:
    """What each route answers, from the served scan (:class:`~volumen.web.ViewerServer` holds one)."""

    def __init__(self, source, scene, camera, budget_mb: float, shift: float):
        self.source, self.scene, self.camera, self.budget_mb, self.shift = source, scene, camera, budget_mb, shift
        self.static = _static()
        self._served: dict[int, ServedVolume] = {}
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="volumen-web")

    def served(self, max_3d: int = DEFAULT_MAX_3D) -> ServedVolume:
        """The volume as a client with ``max_3d`` (its 3-D texture size) gets it, made once per size."""
        max_3d = int(min(max(max_3d, 16), DEFAULT_MAX_3D))
        if max_3d not in self._served:
            self._served[max_3d] = ServedVolume(self.source, max_3d, self.budget_mb)
        return self._served[max_3d]

    async def _work(self, fn, *args):
        return await asyncio.get_running_loop().run_in_executor(self._pool, fn, *args)

    async def index(self, request, path):
        return self.static["index.html"]

    async def static_file(self, request, path):
        return self.static[path.removeprefix("static/")]

    async def info(self, request, path):
        served = self.served(_int(request, "max3d", DEFAULT_MAX_3D))
        from volumen.core import PRESETS, fitted_preset
        from volumen.core._tonemap import shader_constants
        from volumen.render.raster._rc_uniforms import MAX_LIGHTS, MAX_PLANES

        transfers = {name: fitted_preset(name, served.volume).to_dict() for name in PRESETS}
        body = {"volume": served.info(), "scene": self.scene_dict(served), "camera": self.camera.to_dict(),
                "presets": list(PRESETS), "transfers": transfers, "shift": self.shift,
                "notices": list(served.notices), "display": shader_constants(),
                "limits": {"max_lights": MAX_LIGHTS, "max_planes": MAX_PLANES, "budget_mb": self.budget_mb}}
        return json.dumps(body).encode(), "application/json"

    def scene_dict(self, served) -> dict:
        d = self.scene.to_dict()
        d["volume"] = ""  # never the source's path
        return d

    async def shaders(self, request, path):
        from volumen.render.raster._shaders import STAGES, stage_parts

        body = {name: {stage: list(stage_parts(name, stage, "es300")) for stage in STAGES}
                for name in ("raycast", "display")}
        return json.dumps(body).encode(), "application/json"

    async def volume(self, request, path):
        from ._frames import encode

        served = self.served(_int(request, "max3d", DEFAULT_MAX_3D))
        texels, vol_map, exact = await self._work(lambda: served.encoded)
        header = {"shape": list(texels.shape), "vol_map": list(vol_map), "exact": exact,
                  "notices": list(served.notices)}
        return encode(header, {"vol": texels}), "application/octet-stream"

    async def frame(self, request, path):
        from ._frames import encode, web_frame

        body = await request.read()   # past client_max_size (1 MiB): 413
        try:
            req = json.loads(body)
            served = self.served(int(req.get("max3d", DEFAULT_MAX_3D)))
            header, arrays = await self._work(web_frame, served.volume, req["scene"], req["camera"], req["size"])
        except (ValueError, KeyError, TypeError) as exc:
            raise web.HTTPBadRequest(text=_one_line(exc)) from None
        header["seq"] = req.get("seq", 0)
        return encode(header, arrays), "application/octet-stream"

    async def slice(self, request, path):
        from ._slices import slice_png

        served = self.served(_int(request, "max3d", DEFAULT_MAX_3D))
        q = request.query
        try:
            png, m, crossing = await self._work(slice_png, served.volume, q.get("plane", ""),
                                                tuple(float(q.get(a, "nan")) for a in "xyz"),
                                                float(q.get("level", "nan")), float(q.get("width", "nan")))
        except ValueError as exc:
            raise web.HTTPBadRequest(text=_one_line(exc)) from None
        return png, "image/png", {"X-Slice-Map": json.dumps(np.round(m, 6).tolist()),
                                  "X-Slice-Cross": json.dumps(crossing)}

    def close(self):
        self._pool.shutdown(wait=False, cancel_futures=True)


def _int(request, name: str, default: int) -> int:
    try:
        return int(request.query.get(name, default))
    except ValueError:
        raise web.HTTPBadRequest(text=f"{name} must be an integer") from None


def _one_line(exc: Exception) -> str:
    from volumen.errors import VolumenError

    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return text if isinstance(exc, (ValueError, VolumenError)) else f"bad request: {type(exc).__name__} {text}"


class ViewerServer:
    """The viewer's server for one scan: :meth:`start` in a thread (tests, benchmarks, scripts) or
    :meth:`run` in the calling thread (``volumen serve``).

    Parameters
    ----------
    volume : Volume
    scene, camera : Scene, Camera
        What the page opens with (the scene's volume is the served one).
    host : str
        Address to bind; ``127.0.0.1`` by default.
    port : int
        0: a free port.
    budget_mb : float
        Memory budget of the volume texture on the client, MiB.
    token : str or None
        The access token (None: a new random one).
    shift : float
        Where the page's preset shift starts (data units; the scene's transfer function is already shifted).
    ssl_context : ssl.SSLContext or None
        Serve HTTPS (WebXR needs a secure origin on any host but ``localhost``).
    """

    def __init__(self, volume, scene, camera, *, host: str = "127.0.0.1", port: int = 0,
                 budget_mb: float = DEFAULT_BUDGET_MB, token: str | None = None, ssl_context=None, shift: float = 0.0):
        self.host, self.token, self.ssl_context = host, token or new_token(), ssl_context
        self.handlers = _Handlers(volume, scene, camera, budget_mb, shift)
        self.sock = socket.create_server((host, port), family=socket.AF_INET6 if ":" in host else socket.AF_INET)
        self.port = self.sock.getsockname()[1]
        self._loop = self._runner = self._thread = None
        self._stopped = threading.Event()

    @property
    def url(self) -> str:
        """The page's URL with the token (the one line ``volumen serve`` prints first)."""
        scheme = "https" if self.ssl_context else "http"
        host = self.host
        if host in ("0.0.0.0", "::"):
            host = socket.gethostname()
        elif ":" in host:
            host = f"[{host}]"
        return f"{scheme}://{host}:{self.port}/?token={self.token}"

    @property
    def base(self) -> str:
        """The server's origin without the token (tests ask it things without the token)."""
        return self.url.split("/?", 1)[0]

    def _authorized(self, request) -> tuple[bool, bool]:
        """``(authorized, by the query)``: the token from the query, the header or the cookie, constant time."""
        expected = self.token.encode()
        for given, by_query in ((request.query.get("token"), True),
                                (request.headers.get("X-Volumen-Token"), False),
                                (request.cookies.get(self.cookie), False)):
            if given is not None and hmac.compare_digest(given.encode("utf-8", "replace"), expected):
                return True, by_query
        return False, False

    @property
    def cookie(self) -> str:
        return f"volumen-token-{self.port}"

    async def _handle(self, request: web.Request) -> web.StreamResponse:
        t0 = time.perf_counter()
        route, status = "?", 500
        try:
            ok, by_query = self._authorized(request)
            if not ok:
                status = 403
                return web.Response(status=403, text="403: forbidden (this viewer needs the token of its URL)")
            path = request.path.removeprefix("/")
            entry = ROUTES.get(path)
            if entry is None:
                status = 404
                return web.Response(status=404, text="404: not found")
            route = path or "/"
            method, name = entry
            if request.method != method:
                status = 405
                return web.Response(status=405, text=f"405: {route} takes {method}")
            handler = self.handlers.static_file if name == "static" else getattr(self.handlers, name)
            body, ctype, *extra = await handler(request, path)
            headers = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff", **(extra[0] if extra else {})}
            resp = web.Response(body=body, content_type=ctype, headers=headers)
            if by_query:
                resp.set_cookie(self.cookie, self.token, httponly=True, samesite="Strict", path="/",
                                secure=self.ssl_context is not None)
            status = 200
            return resp
        except web.HTTPException as exc:
            status = exc.status
            raise
        finally:
            log.info("%s %s %d %.1f ms", request.method, route if status not in (403, 404) else "-", status,
                     1e3 * (time.perf_counter() - t0))

    def _app(self) -> web.Application:
        app = web.Application(client_max_size=_MAX_BODY)
        app.router.add_route("*", "/{tail:.*}", self._handle)
        return app

    async def _serve(self, ready: threading.Event | None = None) -> None:
        self._runner = web.AppRunner(self._app(), access_log=None, handle_signals=False)
        await self._runner.setup()
        await web.SockSite(self._runner, self.sock, ssl_context=self.ssl_context).start()
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        if ready is not None:
            ready.set()
        try:
            await self._stop.wait()
        finally:
            await self._runner.cleanup()
            self.handlers.close()
            self._stopped.set()

    def run(self) -> None:
        """Serve in the calling thread until interrupted (Ctrl-C) or :meth:`stop`."""
        try:
            asyncio.run(self._serve())
        except KeyboardInterrupt:
            pass

    def start(self) -> ViewerServer:
        """Serve in a background thread; returns once it accepts connections."""
        ready = threading.Event()
        self._thread = threading.Thread(target=lambda: asyncio.run(self._serve(ready)), name="volumen-web-server",
                                        daemon=True)
        self._thread.start()
        if not ready.wait(30):
            raise RuntimeError("the viewer's server did not start within 30 s")
        return self

    def stop(self) -> None:
        """Stop serving and close the socket (waits for the server's thread)."""
        if self._loop is not None and not self._stopped.is_set():
            self._loop.call_soon_threadsafe(self._stop.set)
            self._stopped.wait(30)
        if self._thread is not None:
            self._thread.join(30)
        self.sock.close()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()
