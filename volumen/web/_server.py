"""The viewer's web server (aiohttp): one page, its modules and shaders, and the data of one opened scan.

Privacy and access (the scan is a patient's):

* it binds ``127.0.0.1`` unless told otherwise (``volumen serve --host`` warns in one line when the host is
  not a loopback address);
* every request needs the access token, a random 128-bit number printed once in the URL: in the query
  (``?token=``, the URL's), an ``X-Volumen-Token`` header, or the cookie the first answer sets (``HttpOnly``,
  ``SameSite=Strict``; the page's module imports carry it), which holds an HMAC of the port by the token, not
  the token. Compared in constant time; without it every route answers 403;
* a ``Host`` that is not an IP address, ``localhost``, this machine's name or one of ``names`` (the
  certificate's) answers 403 (DNS rebinding), and so does a POST from another site's page (``Origin``);
* routes are a fixed table (:data:`ROUTES`; the page's files, found in its folder, read into memory at start): no
  part of a request reaches the file system, and anything not in the table (``..``, encoded ``..``,
  absolute paths) answers 404;
* nothing served or logged names the patient: the volume's geometry, modality, units and values only
  (``ServedVolume.info``), never its name, source path or DICOM fields; log lines hold the method, the
  route, the status and the time, never the query (the token) or a path the client sent, and a filter on
  every logger the server uses removes what might (``_redact``).

Limits (connections, deadlines, workers, memory per frame) are :class:`~._serve_limits.ServeLimits`, enforced by
``_connection_guard`` (connections) and ``_handlers`` (work and answers).
"""

from __future__ import annotations

import asyncio
import hashlib
import hmac
import ipaddress
import logging
import secrets
import socket
import threading
import time

from aiohttp import web

from ._connection_guard import GuardedServer, quiet_loop_errors
from ._handlers import MAX_BODY, ROUTES, STATIC_FILES, Handlers, routes
from ._redact import REDACTOR, install
from ._requests import host_allowed, origin_allowed
from ._serve_limits import ServeLimits, connection_cap
from ._served import DEFAULT_BUDGET_MB

__all__ = ["ViewerServer", "new_token", "is_loopback", "ROUTES", "STATIC_FILES", "log"]

log = logging.getLogger("volumen.web")
_COOKIE_PURPOSE = b"volumen serve cookie, port "


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


def _machine_names() -> set[str]:
    """This machine's name (the URL's for ``--host 0.0.0.0``; no DNS look-up at start)."""
    name = socket.gethostname()
    return {name} if name else set()


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
    limits : ServeLimits or None
        Connections, deadlines, workers, memory per frame (None: ``ServeLimits.from_env()``).
    names : iterable of str
        Host names the page may be asked by besides IP addresses, ``localhost`` and this machine's names (the
        certificate's names).
    """

    def __init__(self, volume, scene, camera, *, host: str = "127.0.0.1", port: int = 0,
                 budget_mb: float = DEFAULT_BUDGET_MB, token: str | None = None, ssl_context=None, shift: float = 0.0,
                 limits: ServeLimits | None = None, names=()):
        self.host, self.token, self.ssl_context = host, token or new_token(), ssl_context
        self.limits = limits or ServeLimits.from_env()
        self.handlers = Handlers(volume, scene, camera, budget_mb, shift, self.limits)
        self.routes = routes(self.handlers.static)  # the page's files as read at start
        self.names = {*_machine_names(), *names}
        if not is_loopback(host) and host not in ("0.0.0.0", "::"):
            self.names.add(host)
        self.sock = socket.create_server((host, port), family=socket.AF_INET6 if ":" in host else socket.AF_INET,
                                         backlog=128)
        self.port = self.sock.getsockname()[1]
        self.cookie_value = hmac.new(self.token.encode(), _COOKIE_PURPOSE + str(self.port).encode(),
                                     hashlib.sha256).hexdigest()
        self._secrets = (self.token, self.cookie_value, *_identity(volume))
        self._loop = self._server = self._thread = None
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

    @property
    def cookie(self) -> str:
        """The cookie's name (it carries the port; its value, an HMAC of the port by the token, is no use
        elsewhere)."""
        return f"volumen-token-{self.port}"

    @property
    def open_connections(self) -> int:
        """Connections open now (0 before :meth:`start`)."""
        return self._server.open_connections if self._server is not None else 0

    def _authorized(self, request) -> tuple[bool, bool]:
        """``(authorized, by the query)``: the token from the query or the header, or the cookie's value,
        compared in constant time."""
        for given, expected, by_query in ((request.query.get("token"), self.token, True),
                                          (request.headers.get("X-Volumen-Token"), self.token, False),
                                          (request.cookies.get(self.cookie), self.cookie_value, False)):
            if given is not None and hmac.compare_digest(given.encode("utf-8", "replace"), expected.encode()):
                return True, by_query
        return False, False

    def _refusal(self, request) -> web.Response | None:
        """403 for a foreign ``Host``, a foreign ``Origin`` on a POST, or no token; 404 and 405 for what is not
        a route; None when the request may be served."""
        host = request.headers.get("Host")
        if not host_allowed(host, self.names):
            return web.Response(status=403, text="403: forbidden (this viewer does not answer to that host name)")
        scheme = "https" if self.ssl_context else "http"
        if request.method not in ("GET", "HEAD") and not origin_allowed(request.headers.get("Origin"), host, scheme):
            return web.Response(status=403, text="403: forbidden (a request from another site)")
        if not self._authorized(request)[0]:
            return web.Response(status=403, text="403: forbidden (this viewer needs the token of its URL)")
        entry = self.routes.get(request.path.removeprefix("/"))
        if entry is None:
            return web.Response(status=404, text="404: not found")
        if request.method != entry[0]:
            return web.Response(status=405, text=f"405: {request.path.removeprefix('/') or '/'} takes {entry[0]}")
        return None

    async def _handle(self, request: web.BaseRequest) -> web.StreamResponse:
        t0 = time.perf_counter()
        route, status = "-", 500
        with self._server.busy(request.protocol):
            try:
                resp = self._refusal(request)
                if resp is None:
                    route = request.path.removeprefix("/") or "/"
                    resp = await self._answer(request)
                status = resp.status
                return resp
            except web.HTTPException as exc:
                status = exc.status
                return web.Response(status=exc.status, text=exc.text or f"{exc.status}: {exc.reason}")
            except ConnectionError:   # the client went away while its answer was sent (logged as status 0)
                status = 0
                return web.Response(status=500)
            except Exception as exc:  # noqa: BLE001 - one line and a 500, never a traceback
                log.error("internal error in %s: %s", route, type(exc).__name__)
                return web.Response(status=500, text="500: internal error")
            finally:
                log.info("%s %s %d %.1f ms", request.method if request.method.isalpha() else "?", route, status,
                         1e3 * (time.perf_counter() - t0))

    async def _answer(self, request) -> web.StreamResponse:
        """The route's answer, sent before returning (a large one counts as being sent until it is)."""
        route = request.path.removeprefix("/")
        _, ok_by_query = self._authorized(request)
        with self.handlers.sending(route):
            body, ctype, *extra = await getattr(self.handlers, self.routes[route][1])(request)
            headers = {"Cache-Control": "no-store", "X-Content-Type-Options": "nosniff",
                       **(extra[0] if extra else {})}
            resp = web.StreamResponse(headers=headers)
            resp.content_type, resp.content_length = ctype, len(body)
            if ok_by_query:
                resp.set_cookie(self.cookie, self.cookie_value, httponly=True, samesite="Strict", path="/",
                                secure=self.ssl_context is not None)
            await resp.prepare(request)
            await resp.write(body)
            await resp.write_eof()
            return resp

    def _make_server(self, loop) -> GuardedServer:
        lim = self.limits
        return GuardedServer(self._handle, cap=connection_cap(lim), header_timeout=lim.header_timeout, loop=loop,
                             keepalive_timeout=lim.keepalive_timeout, access_log=None, max_line_size=8190,
                             max_field_size=8190, max_headers=64, handler_cancellation=True,
                             request_factory=lambda *a: web.BaseRequest(*a, loop, client_max_size=MAX_BODY))

    async def _serve(self, ready: threading.Event | None = None) -> None:
        install()
        REDACTOR.add(*self._secrets)
        self._loop = asyncio.get_running_loop()
        quiet_loop_errors(self._loop)
        self._server = self._make_server(self._loop)
        listener = await self._loop.create_server(self._server, sock=self.sock, ssl=self.ssl_context, backlog=128,
                                                  ssl_handshake_timeout=self.limits.header_timeout
                                                  if self.ssl_context else None)
        self._stop = asyncio.Event()
        if ready is not None:
            ready.set()
        try:
            await self._stop.wait()
        finally:
            listener.close()
            self._server.pre_shutdown()
            await self._server.shutdown(2.0)
            self.handlers.close()
            REDACTOR.remove(*self._secrets)
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


def _identity(volume) -> tuple[str, ...]:
    """What in the volume names the patient or the source (redacted from the logs): its name, its source path
    and that path's folder and file names."""
    from pathlib import PurePath

    found = [str(getattr(volume, "name", "") or "")]
    source = (getattr(volume, "meta", None) or {}).get("source")
    if source:
        found += [str(source), *PurePath(str(source)).parts[-2:]]
    return tuple(s for s in found if len(s) >= 3 and s not in ("/", "volume"))
