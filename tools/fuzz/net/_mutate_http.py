"""Mutated HTTP requests to the viewer's server: request lines, headers, bodies and query values.

:func:`make_request` builds request ``k`` of seed ``s`` from a valid one of :func:`seeds` (each route, the token
in the query, a header or the cookie) with one to three mutations of :data:`MUTATIONS`, chosen by a
``random.Random(f"{s}:{k}")``. :func:`send` sends it on a fresh connection and says what came back.
"""

from __future__ import annotations

import gzip
import json
import random
import socket
import time

__all__ = ["seeds", "make_request", "send", "MUTATIONS"]

_ODD_VALUES = [None, [], {}, 1, -1, 0, "x", "", True, 1e308, -1e308, 2 ** 63, 1.5, [1, 2, 3], {"a": 1},
               "\x00", "\u202e", "A" * 5000, json.loads("[" * 20 + "1" + "]" * 20)]
_ODD_TEXT = ["Infinity", "-Infinity", "NaN", "1e999", "-0", "0x10", "1_000", " 1", "%00", "%ff", "..%2f", "€",
             "\x7f", "9" * 400, "", "-1", "65537"]
_ODD_TOKENS = [b"[" * 5000, b"{" * 3000, b"Infinity", b"NaN", b"1e999999", b'"\\ud800"', b"\xff\xfe", b"\x00",
               b",", b"}", b"]", b'"', b"null"]


def seeds(token: str, cookie: str, info: dict) -> list[dict]:
    """Valid requests: ``{"method", "path", "headers" (list of pairs), "body"}``."""
    c = info.get("volume", {}).get("center", [0, 0, 0])
    frame = json.dumps({"scene": info.get("scene", {}), "camera": info.get("camera", {}), "size": [16, 16],
                        "max3d": 256, "seq": 1}).encode()
    host = [("Host", "127.0.0.1")]
    out = []
    for auth in ([("X-Volumen-Token", token)], [("Cookie", cookie)], []):
        q = "" if auth else f"token={token}"
        sep = "&" if q else ""
        out += [{"method": "GET", "path": f"/?{q}", "headers": host + auth, "body": b""},
                {"method": "GET", "path": f"/info.json?max3d=256{sep}{q}", "headers": host + auth, "body": b""},
                {"method": "GET", "path": f"/static/main.js?{q}", "headers": host + auth, "body": b""},
                {"method": "GET", "path": f"/volume.bin?max3d=64{sep}{q}", "headers": host + auth, "body": b""},
                {"method": "GET", "path": f"/slice.png?plane=axial&x={c[0]}&y={c[1]}&z={c[2]}&level=40&width=400"
                                          f"{sep}{q}", "headers": host + auth, "body": b""},
                {"method": "POST", "path": f"/frame.bin?{q}", "headers": host + auth + [
                    ("Content-Type", "application/json")], "body": frame}]
    return out


def _json_paths(value, prefix=()):
    yield prefix
    if isinstance(value, dict):
        for k, v in value.items():
            yield from _json_paths(v, prefix + (k,))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _json_paths(v, prefix + (i,))


def _set(value, path, new):
    if not path:
        return new
    parent = value
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = new
    return value


def _body_value(rng, req):
    try:
        doc = json.loads(req["body"])
    except (ValueError, RecursionError):
        return _body_bytes(rng, req)
    paths = list(_json_paths(doc))
    path = rng.choice(paths)
    if rng.random() < 0.3 and path:
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        del parent[path[-1]]
        req["body"] = json.dumps(doc).encode()
    else:
        req["body"] = json.dumps(_set(doc, path, rng.choice(_ODD_VALUES))).encode()


def _body_bytes(rng, req):
    b = bytearray(req["body"] or b"{}")
    i = rng.randrange(len(b) + 1)
    choice = rng.random()
    if choice < 0.35:
        b[i:i] = rng.choice(_ODD_TOKENS)
    elif choice < 0.6:
        del b[i:]
    elif b:
        b[min(i, len(b) - 1)] = rng.randrange(256)
    req["body"] = bytes(b)


def _gzip(rng, req):
    body = req["body"]
    req["body"] = gzip.compress(body) if rng.random() < 0.5 else b"\x1f\x8b" + body[:40]
    req["headers"].append(("Content-Encoding", rng.choice(["gzip", "deflate", "br", "x-evil"])))


def _query(rng, req):
    path, _, query = req["path"].partition("?")
    parts = [p for p in query.split("&") if p]
    name = rng.choice(["max3d", "plane", "x", "y", "z", "level", "width", "token", "seq", "\x00", "a" * 300])
    value = rng.choice(_ODD_TEXT)
    if parts and rng.random() < 0.6:
        parts[rng.randrange(len(parts))] = f"{name}={value}"
    else:
        parts.append(f"{name}={value}")
    req["path"] = path + "?" + "&".join(parts)


def _path(rng, req):
    path, sep, query = req["path"].partition("?")
    edits = ["/..", "/%2e%2e", "//", "/static/../../etc/passwd", " ", "%00", "/\u00e9", "\\", "/info .json",
             "/" + "a" * 9000, "#frag", "/./", "%", "\t"]
    i = rng.randrange(len(path) + 1)
    req["path"] = path[:i] + rng.choice(edits) + path[i:] + sep + query


def _method(rng, req):
    req["method"] = rng.choice(["PUT", "DELETE", "HEAD", "OPTIONS", "TRACE", "CONNECT", "PATCH", "get", "G\x00T",
                                "POST", "GET", "X" * 300, "", "PRI"])


def _version(rng, req):
    req["version"] = rng.choice(["HTTP/9.9", "HTTP/1.0", "HTTP/2.0", "HTTP/1", "", "HTTPS/1.1", "HTTP/1.1 extra",
                                 "http/1.1"])


def _line_ends(rng, req):
    req["eol"] = rng.choice(["\n", "\r", "\r\r\n", "\n\r"])


def _headers(rng, req):
    h = req["headers"]
    kind = rng.randrange(9)
    if kind == 0 and h:
        h.pop(rng.randrange(len(h)))
    elif kind == 1:
        h.append(("Host", rng.choice(["evil.example", "evil.example:80", "[::1", "", "a" * 300, "127.0.0.1:x"])))
    elif kind == 2:
        h.append(("Origin", rng.choice(["http://evil.example", "null", "http://127.0.0.1:1", "file://", "x"])))
    elif kind == 3:
        h.append(("Content-Length", rng.choice(["-1", "0", "99999999999", "1e3", "abc", "3, 4", str(1 << 21)])))
    elif kind == 4:
        h.append(("Transfer-Encoding", rng.choice(["chunked", "gzip, chunked", "identity", "x"])))
    elif kind == 5:
        h.append(("X-Big", "a" * rng.choice([100, 9000, 70000])))
    elif kind == 6:
        h.append((rng.choice(["Bad Header", "X:Y", "", "\x01"]), "v"))
    elif kind == 7:
        h.extend([("X-Many", "1")] * rng.choice([10, 70, 200]))
    else:
        h.append(("Cookie", rng.choice(["volumen-token-1=x", "a=" + "b" * 5000, "=;;=", "\x00"])))


#: mutation name -> function(rng, request dict), each mutating the request in place
MUTATIONS = {"body-value": _body_value, "body-bytes": _body_bytes, "body-gzip": _gzip, "query": _query,
             "path": _path, "method": _method, "version": _version, "line-ends": _line_ends, "headers": _headers}


def make_request(seed: int, k: int, bases: list[dict]) -> tuple[str, bytes]:
    """``(mutations, raw request)`` of request ``k`` of campaign ``seed``."""
    rng = random.Random(f"{seed}:{k}")
    base = rng.choice(bases)
    req = {**base, "headers": list(base["headers"]), "version": "HTTP/1.1", "eol": "\r\n"}
    names = rng.sample(sorted(MUTATIONS), rng.choice([1, 1, 2, 3]))
    for name in names:
        MUTATIONS[name](rng, req)
    body = req["body"]
    if body and not any(k.lower() in ("content-length", "transfer-encoding") for k, _ in req["headers"]):
        req["headers"].append(("Content-Length", str(len(body))))
    eol = req["eol"]
    head = f"{req['method']} {req['path']} {req['version']}".rstrip() + eol
    head += "".join(f"{k}: {v}{eol}" for k, v in req["headers"]) + eol
    return "+".join(names), head.encode("utf-8", "surrogateescape") + body


def send(port: int, raw: bytes, timeout: float) -> tuple[str, int]:
    """``(outcome, status)``: ``ok`` (2xx/3xx), ``4xx``, ``5xx``, ``closed`` (no answer, the connection closed)
    or ``hang`` (nothing within ``timeout``; then the status is 0)."""
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    end = time.monotonic() + timeout
    try:
        try:
            s.sendall(raw)
        except OSError:
            pass
        data = b""
        while len(data) < 16 and time.monotonic() < end:
            try:
                chunk = s.recv(4096)
            except TimeoutError:
                return "hang", 0
            except OSError:
                break
            if not chunk:
                break
            data += chunk
    finally:
        s.close()
    if time.monotonic() >= end and len(data) < 12:
        return "hang", 0
    if not data.startswith(b"HTTP/1.") or not data[9:12].isdigit():
        return "closed", 0
    status = int(data[9:12])
    return ("ok" if status < 400 else "4xx" if status < 500 else "5xx"), status
