"""What each route of the viewer's server answers, from the served scan; the work behind it in a bounded pool.

Everything that costs more than a dictionary look-up (resampling the volume for a client's texture size,
fitting the presets, encoding the volume, packing a frame, drawing a slice) runs in a pool of
``ServeLimits.workers`` threads, never on the event loop, with at most ``ServeLimits.queue`` requests waiting
(then 429), and at most as many large answers (frames, the volume) are being made or sent at once. Served
volumes are made per power-of-two texture size (:func:`~._serve_limits.cache_size`) and the
``ServeLimits.cached_volumes`` most recently used are kept, each with its ``volume.bin`` message.
"""

from __future__ import annotations

import asyncio
import json
import threading
from collections import OrderedDict
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from importlib import resources

import numpy as np
from aiohttp import web

from volumen.core import PRESETS, fitted_preset
from volumen.core._tonemap import shader_constants
from volumen.errors import VolumenError
from volumen.render.raster._rc_uniforms import MAX_LIGHTS, MAX_PLANES
from volumen.render.raster._shaders import STAGES, stage_parts

from ._frames import FrameBudgetError, encode, web_frame
from ._measure_routes import measurements_answer, pick_answer, region_answer, value_answer
from ._requests import BadRequest, frame_request
from ._serve_limits import ServeLimits, cache_size
from ._served import DEFAULT_MAX_3D, ServedVolume
from ._slices import slice_png

__all__ = ["Handlers", "ROUTES", "STATIC_FILES", "MAX_BODY", "static_folder", "static_files", "routes"]

#: the content type of each kind of file the page is made of
_TYPES = {".html": "text/html", ".css": "text/css", ".js": "text/javascript"}
#: route -> (method, handler name of :class:`Handlers`), besides the page's files
_ANSWERS = {"": ("GET", "index"), "info.json": ("GET", "info"), "shaders.json": ("GET", "shaders"),
            "volume.bin": ("GET", "volume"), "frame.bin": ("POST", "frame"), "slice.png": ("GET", "slice"),
            "region.json": ("POST", "region"), "value.json": ("POST", "value"), "pick.json": ("POST", "pick"),
            "measurements.json": ("GET", "measurements"), "open-measurements.json": ("POST", "open_measurements"),
            "profile.json": ("GET", "vessel_profile")}


def static_folder():
    """The page's folder: package data under ``volumen/web/static``."""
    return resources.files(__package__).joinpath("static")


def static_files(folder=None) -> tuple[str, ...]:
    """The page's files: the names of the files directly in ``folder`` (default :func:`static_folder`) whose
    suffix is a type the page is made of (html, css, js), sorted."""
    root = static_folder() if folder is None else folder
    return tuple(sorted(p.name for p in root.iterdir()
                        if p.is_file() and not p.name.startswith(".") and _suffix(p.name) in _TYPES))


def _suffix(name: str) -> str:
    return "." + name.rsplit(".", 1)[-1] if "." in name else ""


def routes(static_names) -> dict[str, tuple[str, str]]:
    """Route -> (method, handler name of :class:`Handlers`): the answers and ``static/NAME`` for each page file."""
    return {**_ANSWERS, **{f"static/{name}": ("GET", "static_file") for name in static_names}}


#: the page's files, found in its folder, served at ``/`` and ``/static/NAME``
STATIC_FILES = static_files()
#: the routes of a server of the installed page
ROUTES = routes(STATIC_FILES)
#: largest request body (a frame request is a few KiB): past it, 413
MAX_BODY = 1 << 20
#: routes whose answers are large (up to a frame's budget, the volume's texture budget)
_LARGE = ("frame.bin", "volume.bin")


def _static() -> dict[str, tuple[bytes, str]]:
    """The page's files read into memory: name -> (bytes, content type)."""
    root = static_folder()
    return {name: (root.joinpath(name).read_bytes(), _TYPES[_suffix(name)]) for name in static_files(root)}


def _query_int(request, name: str, default: int) -> int:
    text = request.query.get(name)
    if text is None:
        return default
    if not (text.isascii() and text.isdigit() and len(text) <= 6):
        raise web.HTTPBadRequest(text=f"{name} must be a positive integer")
    return int(text)


def _query_float(request, name: str) -> float:
    try:
        value = float(request.query.get(name, "nan"))
    except ValueError:
        raise web.HTTPBadRequest(text=f"{name} must be a number") from None
    if not np.isfinite(value):
        raise web.HTTPBadRequest(text=f"{name} must be a finite number")
    return value


class Handlers:
    """The routes' answers for one scan (:class:`~volumen.web.ViewerServer` holds one).

    Each route's method takes the request and returns ``(body, content type[, headers])``; a request that
    cannot be served raises an ``aiohttp.web.HTTPException`` with a one-line text.
    """

    def __init__(self, source, scene, camera, budget_mb: float, shift: float, limits: ServeLimits):
        self.source, self.scene, self.camera, self.budget_mb, self.shift = source, scene, camera, budget_mb, shift
        self.limits = limits
        self.static = _static()
        self._served: OrderedDict[int, ServedVolume] = OrderedDict()
        self._served_lock = threading.Lock()
        self._pool = ThreadPoolExecutor(max_workers=limits.workers, thread_name_prefix="volumen-web")
        self._waiting = self._sending = 0
        self._messages: dict[int, bytes] = {}   # volume.bin's message per served size, shared by every answer
        self.opening: list[dict] = []   # the measurements the page opens with (``volumen serve --measurements``)
        self.profile: dict | None = None   # the vessel profile it plots (``volumen serve --report``)

    def served(self, max_3d: int = DEFAULT_MAX_3D) -> ServedVolume:
        """The volume as a client with ``max_3d`` (its 3-D texture size) gets it: made once per power of two,
        the ``limits.cached_volumes`` most recently used kept."""
        size = cache_size(max_3d)
        with self._served_lock:
            if size in self._served:
                self._served.move_to_end(size)
                return self._served[size]
            while len(self._served) >= self.limits.cached_volumes:
                self._messages.pop(self._served.popitem(last=False)[0], None)
            served = self._served[size] = ServedVolume(self.source, size, self.budget_mb)
            return served

    @property
    def cached_sizes(self) -> list[int]:
        """The texture sizes whose served volumes are kept, least recently used first."""
        return list(self._served)

    async def work(self, fn, *args):
        """``fn(*args)`` in the worker pool; 429 when ``limits.queue`` requests are already waiting."""
        if self._waiting >= self.limits.queue:
            raise web.HTTPTooManyRequests(text=f"429: busy ({self._waiting} requests waiting); ask again")
        self._waiting += 1
        try:
            return await asyncio.get_running_loop().run_in_executor(self._pool, fn, *args)
        finally:
            self._waiting -= 1

    @contextmanager
    def sending(self, route: str):
        """Around a large answer (a frame, the volume) until it is sent: at most ``limits.queue`` at once (429),
        so clients that read slowly cannot pile answers up in memory."""
        if route not in _LARGE:
            yield
            return
        if self._sending >= self.limits.queue:
            raise web.HTTPTooManyRequests(text=f"429: busy ({self._sending} large answers being sent); ask again")
        self._sending += 1
        try:
            yield
        finally:
            self._sending -= 1

    async def index(self, request):
        return self.static["index.html"]

    async def static_file(self, request):
        return self.static[request.path.removeprefix("/static/")]

    async def info(self, request):
        body = await self.work(self._info, _query_int(request, "max3d", DEFAULT_MAX_3D))
        return body, "application/json"

    def _info(self, max_3d: int) -> bytes:
        served = self.served(max_3d)
        transfers = {name: fitted_preset(name, served.volume).to_dict() for name in PRESETS}
        scene = self.scene.to_dict()
        scene["volume"] = ""  # never the source's path
        body = {"volume": served.info(), "scene": scene, "camera": self.camera.to_dict(),
                "presets": list(PRESETS), "transfers": transfers, "shift": self.shift,
                "notices": list(served.notices), "display": shader_constants(),
                "limits": {"max_lights": MAX_LIGHTS, "max_planes": MAX_PLANES, "budget_mb": self.budget_mb,
                           "frame_mb": self.limits.frame_mb}}
        return json.dumps(body).encode()

    async def shaders(self, request):
        body = {name: {stage: list(stage_parts(name, stage, "es300")) for stage in STAGES}
                for name in ("raycast", "display")}
        return json.dumps(body).encode(), "application/json"

    async def volume(self, request):
        return await self.work(self._volume, _query_int(request, "max3d", DEFAULT_MAX_3D)), "application/octet-stream"

    def _volume(self, max_3d: int) -> bytes:
        served, size = self.served(max_3d), cache_size(max_3d)
        with self._served_lock:
            if size in self._messages:
                return self._messages[size]
        texels, vol_map, exact = served.encoded
        header = {"shape": list(texels.shape), "vol_map": list(vol_map), "exact": exact,
                  "notices": list(served.notices)}
        message = encode(header, {"vol": texels})
        with self._served_lock:
            if size in self._served:
                self._messages[size] = message
        return message

    async def body(self, request) -> bytes:
        """A POST's body, within ``limits.body_timeout`` and :data:`MAX_BODY` (408, 413, 400 otherwise)."""
        try:
            async with asyncio.timeout(self.limits.body_timeout):
                return await request.read()   # past MAX_BODY: 413
        except TimeoutError:
            raise web.HTTPRequestTimeout(text=f"408: the body did not arrive within {self.limits.body_timeout:g} s"
                                         ) from None
        except web.HTTPException:
            raise
        except Exception as exc:  # noqa: BLE001 - a payload aiohttp cannot read: bad gzip, broken chunks
            raise web.HTTPBadRequest(text=f"the body could not be read ({type(exc).__name__})") from None

    async def region(self, request):
        """A region's statistics over the scan's own voxels (not the served, maybe coarser, copy):
        ``{"plane": {"origin", "u", "v"}, "shape": {...}}`` (``volumen.measure``) -> numbers and units only."""

        body = await self.body(request)
        return await self.work(region_answer, self.source, body), "application/json"

    async def value(self, request):
        """The scan's own value at a point (``{"point": [x, y, z]}`` mm) -> ``{"value", "units"}`` or null."""

        body = await self.body(request)
        return await self.work(value_answer, self.source, body), "application/json"

    async def measurements(self, request):
        """The measurements the page opens with, as ``volumen.measure.Measurements.to_dicts``."""

        return json.dumps({"measurements": self.opening}).encode(), "application/json"

    async def vessel_profile(self, request):
        """The vessel profile the page plots under its slices (:func:`~._profile_route.read_profile`), or null."""

        return json.dumps({"profile": self.profile}).encode(), "application/json"

    async def open_measurements(self, request):
        """The measurements of a file the user opens on the page (its bytes), checked against the scan."""

        body = await self.body(request)
        return await self.work(measurements_answer, self.source, body), "application/json"

    async def pick(self, request):
        """The first visible surface under a point of the 3-D picture, in the served volume (the page's)."""

        body = await self.body(request)
        try:
            max3d = int(json.loads(body)["frame"].get("max3d", DEFAULT_MAX_3D))
        except (ValueError, KeyError, TypeError, AttributeError):
            max3d = DEFAULT_MAX_3D  # pick_answer says what is wrong with the body
        served = self.served(max(1, min(max3d, DEFAULT_MAX_3D)))
        return await self.work(pick_answer, served.volume, body), "application/json"

    async def frame(self, request):
        body = await self.body(request)
        try:
            req = frame_request(body)
        except BadRequest as exc:
            raise web.HTTPBadRequest(text=str(exc)) from None
        return await self.work(self._frame, req), "application/octet-stream"

    def _frame(self, req) -> bytes:
        served = self.served(req.max3d if req.max3d is not None else DEFAULT_MAX_3D)
        try:
            header, arrays = web_frame(served.volume, req.scene, req.camera, req.size,
                                       budget_bytes=self.limits.frame_mb * 2 ** 20)
        except FrameBudgetError as exc:
            raise web.HTTPRequestEntityTooLarge(self.limits.frame_mb * 2 ** 20, 0, text=_one_line(exc)) from None
        except (ValueError, KeyError, TypeError, AttributeError, OverflowError, IndexError, VolumenError) as exc:
            raise web.HTTPBadRequest(text=_one_line(exc)) from None
        header["seq"] = req.seq
        return encode(header, arrays)

    async def slice(self, request):
        max_3d = _query_int(request, "max3d", DEFAULT_MAX_3D)
        plane = request.query.get("plane", "")
        world = tuple(_query_float(request, a) for a in "xyz")
        level, width = _query_float(request, "level"), _query_float(request, "width")
        try:
            png, m, crossing = await self.work(lambda: slice_png(self.served(max_3d).volume, plane, world, level,
                                                                 width))
        except ValueError as exc:
            raise web.HTTPBadRequest(text=_one_line(exc)) from None
        return png, "image/png", {"X-Slice-Map": json.dumps(np.round(m, 6).tolist()),
                                  "X-Slice-Cross": json.dumps(crossing)}

    def close(self):
        self._pool.shutdown(wait=False, cancel_futures=True)


def _one_line(exc: Exception) -> str:
    """An error's first line, at most 200 characters."""
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return text[:200]
