"""What one viewer server allows a client: connections, deadlines, worker threads, memory per frame.

Every limit is a field of :class:`ServeLimits`, declared once here; ``volumen serve`` reads each from an
environment variable named after it (``VOLUMEN_SERVE_MAX_CONNECTIONS=32``, ``VOLUMEN_SERVE_FRAME_MB=128``...)
and otherwise uses the defaults below, which a browser and a headset never come near.
"""

from __future__ import annotations

import os
import resource
from dataclasses import dataclass, fields

__all__ = ["ServeLimits", "connection_cap", "cache_size"]

#: file descriptors kept free of connections (the listening socket, the volume's files, logs, Numba's cache)
_RESERVED_FDS = 64
#: smallest and largest 3-D texture size a client may state (a served volume is made per power of two between)
MIN_3D, MAX_3D = 16, 2048


@dataclass(frozen=True, kw_only=True)
class ServeLimits:
    """The server's limits (environment: ``VOLUMEN_SERVE_`` + the field's name in capitals).

    Parameters
    ----------
    max_connections : int
        Open connections at most (fewer when the process's file limit is low: it keeps 64 descriptors free).
        A connection past the cap closes the oldest one that is not in the middle of a request, else itself.
    header_timeout : float, s
        A request's line and headers must arrive whole within this time of its first byte (or of the
        connection's opening); else the connection is closed.
    body_timeout : float, s
        A request's body must arrive whole within this time of its headers (else 408).
    keepalive_timeout : float, s
        An idle connection between two requests is closed after this time.
    workers : int
        Threads that resample the volume and pack frames (never the event loop).
    queue : int
        Requests in the worker pool (running or waiting) at most; past it a request answers 429.
    cached_volumes : int
        Resampled volumes kept (one per power-of-two texture size asked for), least recently used dropped.
    frame_mb : float, MiB
        Memory one frame may allocate (tables and illumination volumes); past it the frame answers 413.
    """

    max_connections: int = 64
    header_timeout: float = 10.0
    body_timeout: float = 10.0
    keepalive_timeout: float = 5.0
    workers: int = 2
    queue: int = 8
    cached_volumes: int = 2
    frame_mb: float = 512.0

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if not (value > 0 and value < float("inf")):
                raise ValueError(f"ServeLimits.{f.name} must be a positive finite number, got {value!r}")

    @classmethod
    def from_env(cls, environ=None) -> ServeLimits:
        """The limits with each ``VOLUMEN_SERVE_<NAME>`` set in ``environ`` (default ``os.environ``) applied."""
        environ = os.environ if environ is None else environ
        given = {}
        for f in fields(cls):
            text = environ.get(f"VOLUMEN_SERVE_{f.name.upper()}")
            if text is None:
                continue
            kind = int if f.type in ("int", int) else float
            try:
                given[f.name] = kind(text)
            except ValueError:
                raise ValueError(f"VOLUMEN_SERVE_{f.name.upper()} must be a{'n integer' if kind is int else ' number'}"
                                 f", got {text!r}") from None
        return cls(**given)


def connection_cap(limits: ServeLimits) -> int:
    """``limits.max_connections``, lowered so the connections leave 64 of the process's file descriptors free
    (an ``accept()`` past the file limit fails; at least 4 connections)."""
    soft, _ = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft == resource.RLIM_INFINITY:
        return limits.max_connections
    return max(4, min(limits.max_connections, soft - _RESERVED_FDS))


def cache_size(max_3d) -> int:
    """The texture size a served volume is made for: the largest power of two at most ``max_3d``, within
    16..2048 (a client stating 700 gets the 512 volume: a few sizes, not one per value asked)."""
    n = int(min(max(max_3d, MIN_3D), MAX_3D))
    return 1 << (n.bit_length() - 1)
