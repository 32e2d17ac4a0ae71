"""Keep the access token and the patient out of every log line the viewer's server causes.

The server's own lines hold a method, a route, a status and a time; but aiohttp and asyncio log what they
meet (a malformed request line with its query, an exception with its traceback). :class:`Redactor` is a
``logging.Filter`` put on every logger the server uses (:data:`LOGGERS`, aiohttp's included) while a server
runs: it replaces each secret it was given (the token, the cookie's value, the patient's name, the source
path) and every ``token=`` value by ``...``, keeps only a message's first line, cut to 300 characters, and
drops tracebacks.
"""

from __future__ import annotations

import logging
import re
import threading

__all__ = ["Redactor", "REDACTOR", "LOGGERS", "install"]

#: every logger a request can reach: the server's own, aiohttp's and the event loop's
LOGGERS = ("volumen.web", "aiohttp.access", "aiohttp.server", "aiohttp.web", "aiohttp.internal", "aiohttp.client",
           "aiohttp.websocket", "asyncio")
_QUERY_TOKEN = re.compile(r"(token=)[^&\s\"'#]*", re.IGNORECASE)
_LONGEST = 300


class Redactor(logging.Filter):
    """A log filter that removes secrets, tracebacks and everything past a message's first line."""

    def __init__(self):
        super().__init__()
        self._secrets: dict[str, int] = {}
        self._lock = threading.Lock()

    def add(self, *secrets: str) -> None:
        """Redact these strings (empty and very short ones are ignored) until :meth:`remove`."""
        with self._lock:
            for s in secrets:
                if s and len(s) >= 3:
                    self._secrets[s] = self._secrets.get(s, 0) + 1

    def remove(self, *secrets: str) -> None:
        with self._lock:
            for s in secrets:
                if s in self._secrets:
                    self._secrets[s] -= 1
                    if not self._secrets[s]:
                        del self._secrets[s]

    def redact(self, text: str) -> str:
        """``text`` on one line, without the secrets and ``token=`` values."""
        first = text.splitlines()[0] if text else ""
        with self._lock:
            secrets = sorted(self._secrets, key=len, reverse=True)
        for s in secrets:
            if s in first:
                first = first.replace(s, "...")
            elif s.lower() in first.lower():
                first = re.sub(re.escape(s), "...", first, flags=re.IGNORECASE)
        first = _QUERY_TOKEN.sub(r"\1...", first)
        return first if len(first) <= _LONGEST else first[:_LONGEST] + "..."

    def filter(self, record: logging.LogRecord) -> bool:
        try:
            message = record.getMessage()
        except Exception:  # noqa: BLE001 - arguments that do not format: keep the template only
            message = str(record.msg)
        record.msg, record.args = self.redact(message), ()
        record.exc_info = record.exc_text = record.stack_info = None
        return True


#: the one filter of every server in the process
REDACTOR = Redactor()


def install() -> None:
    """Put :data:`REDACTOR` on every logger of :data:`LOGGERS` (idempotent)."""
    for name in LOGGERS:
        logger = logging.getLogger(name)
        if REDACTOR not in logger.filters:
            logger.addFilter(REDACTOR)
