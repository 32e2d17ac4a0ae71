"""Connections under guard: a cap on open connections, a deadline for a request's headers, quiet accept errors.

aiohttp closes a connection that waits for a request longer than ``keepalive_timeout`` and accepts connections
until the process runs out of file descriptors. :class:`GuardedServer` (aiohttp's low-level ``web.Server``) adds:

* **a cap**: a connection past :func:`~._serve_limits.connection_cap` closes the oldest connection that is not
  inside a request (idle, or still sending its headers), else itself: idle clients cannot lock out one
  that asks something;
* **a header deadline** of its own, whatever the keep-alive allows: from its opening, and from the first byte
  of each later request, a connection has ``header_timeout`` seconds to deliver a request's line and headers,
  else it is closed;
* **short error answers**: a malformed request (a bad request line, an HTTP version it does not speak, bare
  line feeds) answers 400 with one plain line, and the log gets one line without the request's text.

:func:`quiet_loop_errors` turns the event loop's reports (``accept()`` out of file descriptors, which asyncio
repeats as fast as clients connect) into one log line, at most every 10 s, with the count since the last.
"""

from __future__ import annotations

import errno
import logging
import time
from contextlib import contextmanager

from aiohttp import web
from aiohttp.web_protocol import RequestHandler

__all__ = ["GuardedServer", "quiet_loop_errors"]

log = logging.getLogger("volumen.web")

_RESOURCE_ERRNOS = (errno.EMFILE, errno.ENFILE, errno.ENOBUFS, errno.ENOMEM)
_REPORT_EVERY = 10.0


class _Connection(RequestHandler):
    """aiohttp's connection handler, reporting to its :class:`GuardedServer`."""

    def connection_made(self, transport) -> None:
        super().connection_made(transport)
        self._manager.guard_opened(self)

    def connection_lost(self, exc) -> None:
        self._manager.guard_closed(self)
        super().connection_lost(exc)

    def data_received(self, data: bytes) -> None:
        self._manager.guard_data(self)
        super().data_received(data)

    def log_exception(self, *args, **kw) -> None:
        """aiohttp's reports (a body it could not decode while draining it, ...): one line, the exception's type."""
        exc = kw.get("exc_info")
        what = type(exc).__name__ if isinstance(exc, BaseException) else ""
        log.info("connection: %s %s", str(args[0]) if args else "", what)

    def handle_error(self, request, status: int = 500, exc=None, message=None):
        """One plain line to the client, one line to the log (no request text, no traceback)."""
        if status >= 500:
            log.error("internal error: %s", type(exc).__name__ if exc is not None else "unknown")
            text = "500: internal error"
        else:
            log.info("malformed request: %d %s", status, type(exc).__name__ if exc is not None else "")
            text = f"{status}: malformed request"
        resp = web.Response(status=status, text=text)
        resp.force_close()
        return resp


class GuardedServer(web.Server):
    """``web.Server`` with a cap on connections and a deadline for a request's headers (see the module).

    Parameters
    ----------
    handler : coroutine function
        The request handler (low-level: it gets a ``BaseRequest``); it runs inside :meth:`busy`.
    cap : int
        Open connections at most.
    header_timeout : float, s
    **kwargs
        aiohttp's ``RequestHandler`` settings (``keepalive_timeout``, ``max_line_size``...).
    """

    def __init__(self, handler, *, cap: int, header_timeout: float, **kwargs):
        super().__init__(handler, **kwargs)
        self.cap, self.header_timeout = cap, header_timeout
        self._open: dict[RequestHandler, object] = {}   # connection -> its header deadline (a timer) or None
        self._busy: set[RequestHandler] = set()
        self.evicted = 0

    def __call__(self) -> RequestHandler:
        return _Connection(self, loop=self._loop, **self._kwargs)

    def guard_opened(self, conn) -> None:
        if len(self._open) >= self.cap:
            idle = next((c for c in self._open if c not in self._busy), None)
            if idle is None:
                conn.force_close()
                return
            self.evicted += 1
            self._close(idle)
        self._open[conn] = None
        self._arm(conn)

    def guard_closed(self, conn) -> None:
        timer = self._open.pop(conn, None)
        if timer is not None:
            timer.cancel()
        self._busy.discard(conn)

    def guard_data(self, conn) -> None:
        if conn in self._open and conn not in self._busy and self._open[conn] is None:
            self._arm(conn)

    def _arm(self, conn) -> None:
        self._open[conn] = self._loop.call_later(self.header_timeout, self._close, conn)

    def _close(self, conn) -> None:
        self.guard_closed(conn)
        conn.force_close()

    @contextmanager
    def busy(self, conn):
        """Inside a request: the connection is neither evicted nor held to the header deadline."""
        timer = self._open.get(conn)
        if timer is not None:
            timer.cancel()
            self._open[conn] = None
        self._busy.add(conn)
        try:
            yield
        finally:
            self._busy.discard(conn)

    @property
    def open_connections(self) -> int:
        return len(self._open)


def quiet_loop_errors(loop) -> None:
    """Report the event loop's errors in one line each, resource errors at most every 10 s with a count."""
    state = {"last": -_REPORT_EVERY, "count": 0}

    def handler(loop, context):
        exc = context.get("exception")
        if isinstance(exc, OSError) and exc.errno in _RESOURCE_ERRNOS:
            state["count"] += 1
            now = time.monotonic()
            if now - state["last"] >= _REPORT_EVERY:
                log.warning("refusing connections for a moment: %s (%d time(s) in the last %.0f s)",
                            exc.strerror or type(exc).__name__, state["count"], _REPORT_EVERY)
                state["last"], state["count"] = now, 0
            return
        what = type(exc).__name__ if exc is not None else ""
        log.error("event loop: %s %s", str(context.get("message", "")).splitlines()[0][:120], what)

    loop.set_exception_handler(handler)
