"""What a request may hold: the frame request's JSON body, checked before anything is computed; the ``Host``
and ``Origin`` a browser sends.

:func:`frame_request` reads the body of ``frame.bin`` into a :class:`FrameRequest` or raises
:class:`BadRequest` (a ``ValueError`` whose message is one short line): an object of the keys of
:data:`FRAME_KEYS` with their types, finite numbers only (``Infinity``, ``NaN``, ``1e999`` refused), nested at
most :data:`MAX_DEPTH` deep, ``size`` two integers of 1..8192, ``max3d`` an integer of 1..65536.

:func:`host_allowed` is the defence against DNS rebinding (a page of ``evil.example`` whose name comes to
resolve to this machine reaches it with ``Host: evil.example``): a ``Host`` must be an IP address (a browser
that asks an address by its digits was not rebound), ``localhost``, or one of the names given (the machine's
name, the certificate's). :func:`origin_allowed` keeps other sites' pages from asking for frames.
"""

from __future__ import annotations

import ipaddress
import json
import math
from dataclasses import dataclass
from urllib.parse import urlsplit

__all__ = ["BadRequest", "FrameRequest", "frame_request", "parse_json", "host_allowed", "origin_allowed",
           "FRAME_KEYS", "MAX_DEPTH"]

#: the keys of a frame request -> what each must be
FRAME_KEYS = {"scene": "an object", "camera": "an object", "size": "[width, height]",
              "max3d": "an integer", "seq": "a number"}
#: arrays and objects nested at most this deep in a request's body (a scene nests 5 levels)
MAX_DEPTH = 12
_MAX_SIDE, _MAX_3D = 8192, 65536


class BadRequest(ValueError):
    """A request that cannot be served as it is (400), with a one-line reason."""


@dataclass(frozen=True)
class FrameRequest:
    """A validated ``frame.bin`` body: ``scene`` and ``camera`` as ``Scene.to_dict`` and ``Camera.to_dict``
    write them (validated later by ``Scene.from_dict``), the picture's ``size``, the client's ``max3d`` (None:
    not given) and ``seq`` (echoed)."""

    scene: dict
    camera: dict
    size: tuple[int, int]
    max3d: int | None
    seq: float


def _finite(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise BadRequest(f"numbers must be finite, got {text[:20]}")
    return value


def _constant(name: str):
    raise BadRequest(f"numbers must be finite, got {name}")


def _depth(value, limit: int) -> None:
    stack = [(value, 1)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, (dict, list)):
            if d > limit:
                raise BadRequest(f"the body nests more than {limit} levels deep")
            stack.extend((x, d + 1) for x in (v.values() if isinstance(v, dict) else v))


def parse_json(body: bytes, max_depth: int = MAX_DEPTH):
    """The JSON value of ``body``: UTF-8, finite numbers, at most ``max_depth`` levels; else :class:`BadRequest`."""
    try:
        value = json.loads(body.decode("utf-8"), parse_float=_finite, parse_constant=_constant)
    except BadRequest:
        raise
    except RecursionError:
        raise BadRequest(f"the body nests more than {max_depth} levels deep") from None
    except UnicodeDecodeError:
        raise BadRequest("the body is not UTF-8 text") from None
    except ValueError as exc:
        raise BadRequest(f"the body is not JSON ({str(exc).splitlines()[0][:80]})") from None
    _depth(value, max_depth)
    return value


def _integer(value, name: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != int(value):
        raise BadRequest(f"{name} must be an integer, got {json.dumps(value)[:40]}")
    if not lo <= value <= hi:
        raise BadRequest(f"{name} must be {lo}..{hi}, got {int(value)}")
    return int(value)


def frame_request(body: bytes) -> FrameRequest:
    """The frame request of ``body`` (see the module's docstring); :class:`BadRequest` naming what is wrong."""
    req = parse_json(body)
    if not isinstance(req, dict):
        raise BadRequest("the body must be a JSON object {scene, camera, size}")
    unknown = sorted(set(req) - set(FRAME_KEYS))
    if unknown:
        raise BadRequest(f"unknown key {unknown[0][:40]!r}; valid: {', '.join(FRAME_KEYS)}")
    for key in ("scene", "camera", "size"):
        if key not in req:
            raise BadRequest(f"the body needs {key} ({FRAME_KEYS[key]})")
    for key in ("scene", "camera"):
        if not isinstance(req[key], dict):
            raise BadRequest(f"{key} must be {FRAME_KEYS[key]}")
    size = req["size"]
    if not isinstance(size, list) or len(size) != 2:
        raise BadRequest("size must be [width, height]")
    w, h = (_integer(v, "size", 1, _MAX_SIDE) for v in size)
    max3d = _integer(req["max3d"], "max3d", 1, _MAX_3D) if "max3d" in req else None
    seq = req.get("seq", 0)
    if isinstance(seq, bool) or not isinstance(seq, (int, float)):
        raise BadRequest("seq must be a number")
    return FrameRequest(req["scene"], req["camera"], (w, h), max3d, seq)


def _host_name(host: str) -> str | None:
    """The name or address of a ``Host`` header without its port (None: not a host)."""
    host = host.strip().lower()
    if host.startswith("["):
        end = host.find("]")
        rest = host[end + 1:] if end > 0 else None
        if rest is None or (rest and not (rest[0] == ":" and rest[1:].isdigit())):
            return None
        return host[1:end]
    name, _, port = host.partition(":")
    if port and not port.isdigit():
        return None
    return name.rstrip(".")


def host_allowed(host: str | None, names) -> bool:
    """Whether a request's ``Host`` (None: not sent, not a browser) names this server: an IP address,
    ``localhost`` or one of ``names``."""
    if host is None:
        return True
    name = _host_name(host)
    if not name:
        return False
    try:
        ipaddress.ip_address(name)
        return True
    except ValueError:
        return name == "localhost" or name in {n.lower().rstrip(".") for n in names}


def origin_allowed(origin: str | None, host: str | None, scheme: str) -> bool:
    """Whether a state-changing request's ``Origin`` (None: not sent, not a browser) is this server's own."""
    if origin is None:
        return True
    parts = urlsplit(origin.strip().lower())
    return bool(host) and parts.scheme == scheme and parts.netloc == host.strip().lower() and not parts.path
