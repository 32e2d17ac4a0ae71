"""Mutated DICOMweb answers from a hostile archive against ``volumen pacs find`` and ``volumen pacs get``.

Reply ``k`` of seed ``s`` (a ``random.Random(f"{s}:{k}")``) picks an operation of :data:`OPERATIONS` (a study
search as a table or as JSON, a series search, a retrieve: the instance list, then one instance), the one of
its answers to spoil, and one or two mutations of :data:`MUTATIONS` (values, structure, bytes, status, headers,
an endless body, a dribbled one). :func:`run_reply` runs the ``volumen.pacs`` function behind the command in
this process against the archive and says how it ended (the command prints an ``ArchiveError`` as one line and
exits 1; ``tests/pacs/test_pacs_hostile.py`` runs the command itself).
"""

from __future__ import annotations

import gzip
import io
import json
import random
import time
import warnings
from functools import cache

from ._archive import HostileArchive, Reply, dataset_json, endless

__all__ = ["OPERATIONS", "MUTATIONS", "make_reply", "run_reply", "instance_bytes"]

STUDY, SERIES = "1.2.826.0.1.3680043.8.498.1", "1.2.826.0.1.3680043.8.498.2"
INSTANCE = "1.2.826.0.1.3680043.8.498.3"
_BOUNDARY = "volumen-fuzz-boundary"
_HOSTILE_TEXT = ["\x1b]0;pwned\x07", "\x1b[2J\x1b[H", "ID\r\n2024  CT  1  Forged^Row", "\u202eevil", "\x00",
                 "\t", "\x9b31m", "A" * 10000, "\ud800", "\u2028", "é中", ""]
_ODD = [None, [], {}, 1, -1, "x", True, 1e308, [1, 2], {"vr": "PN"}, {"vr": 5}, {"Value": "x"},
        {"vr": "PN", "Value": [{"Alphabetic": 7}]}, {"vr": "UI", "Value": [None]}, {"vr": "IS", "Value": ["abc"]},
        {"vr": "DA", "Value": ["not a date"]}, {"vr": "SQ", "Value": [{"x": 1}]}]


def _studies() -> bytes:
    return json.dumps([dataset_json(PatientName=f"Doe^Jane{i}", PatientID=f"P{i}", StudyInstanceUID=f"{STUDY}{i}",
                                    StudyDate="20240102", StudyDescription="CT chest", AccessionNumber="A1",
                                    ModalitiesInStudy="CT") for i in range(3)]).encode()


def _series() -> bytes:
    return json.dumps([dataset_json(StudyInstanceUID=STUDY, SeriesInstanceUID=f"{SERIES}{i}", SeriesNumber="1",
                                    Modality="CT", SeriesDescription="axial") for i in range(2)]).encode()


def _instances() -> bytes:
    return json.dumps([dataset_json(SOPInstanceUID=INSTANCE)]).encode()


@cache
def instance_bytes() -> bytes:
    """A small CT image (8 x 8, int16) as a DICOM Part 10 file."""
    import numpy as np
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian

    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID = CTImageStorage, INSTANCE
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID, ds.SOPInstanceUID = CTImageStorage, INSTANCE
    ds.StudyInstanceUID, ds.SeriesInstanceUID, ds.Modality = STUDY, SERIES, "CT"
    ds.Rows = ds.Columns = 8
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
    ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
    ds.PixelSpacing, ds.ImagePositionPatient = [1, 1], [0, 0, 0]
    ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
    ds.PixelData = np.arange(64, dtype=np.int16).tobytes()
    buf = io.BytesIO()
    ds.save_as(buf, enforce_file_format=True)
    return buf.getvalue()


def _multipart(part: bytes) -> bytes:
    return (f"--{_BOUNDARY}\r\nContent-Type: application/dicom\r\n\r\n".encode() + part
            + f"\r\n--{_BOUNDARY}--\r\n".encode())


_MULTIPART = {"Content-Type": f'multipart/related; type="application/dicom"; boundary={_BOUNDARY}'}

#: operation (``volumen pacs find``, ``find --json``, ``find --study``, ``get``) -> its answers in order
OPERATIONS = {"find": [(_studies, {})], "find-json": [(_studies, {})], "series": [(_series, {})],
              "get": [(_instances, {}), (lambda: _multipart(instance_bytes()), _MULTIPART)]}


def _walk(value, path=()):
    yield path
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for k, v in items:
        yield from _walk(v, path + (k,))


def _json_edit(rng, reply: Reply, delete: bool = False):
    try:
        doc = json.loads(reply.body)
    except (ValueError, TypeError, RecursionError):
        return _bytes(rng, reply)
    path = rng.choice(list(_walk(doc)))
    if not path:
        doc = rng.choice(_ODD)
    else:
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        if delete:
            del parent[path[-1]]
        else:
            parent[path[-1]] = rng.choice(_ODD + _HOSTILE_TEXT)
    reply.body = json.dumps(doc).encode()


def _text(rng, reply: Reply):
    try:
        doc = json.loads(reply.body)
    except (ValueError, TypeError, RecursionError):
        return _bytes(rng, reply)
    strings = [p for p in _walk(doc) if p and isinstance(_get(doc, p), str)]
    if strings:
        path = rng.choice(strings)
        _get(doc, path[:-1])[path[-1]] = rng.choice(_HOSTILE_TEXT) + rng.choice(["", _get(doc, path)])
    reply.body = json.dumps(doc).encode()


def _get(doc, path):
    for key in path:
        doc = doc[key]
    return doc


def _bytes(rng, reply: Reply):
    b = bytearray(reply.body)
    i = rng.randrange(len(b) + 1)
    r = rng.random()
    if r < 0.3:
        b[i:i] = rng.choice([b"[" * 5000, b"\x00", b"\xff\xfe", b"Infinity", b"}", b'"',
                             b"\r\n--" + _BOUNDARY.encode()])
    elif r < 0.6:
        del b[i:]
    else:
        for _ in range(rng.randint(1, 8)):
            if b:
                b[rng.randrange(len(b))] = rng.randrange(256)
    reply.body = bytes(b)


def _status(rng, reply: Reply, other: str):
    code = rng.choice([204, 301, 302, 307, 308, 400, 401, 403, 404, 409, 500, 503])
    reply.status = code
    if 300 <= code < 400:
        reply.headers["Location"] = rng.choice([other + "/studies", "/elsewhere", "ftp://x/", "", "//evil.example/x"])


def _headers(rng, reply: Reply):
    kind = rng.randrange(5)
    if kind == 0:
        reply.headers["Content-Type"] = rng.choice(["text/html", "application/json", "multipart/related", "",
                                                    "multipart/related; boundary="])
    elif kind == 1 and isinstance(reply.body, bytes):
        reply.headers["Content-Length"] = str(len(reply.body) + rng.choice([1, 1000]))
    elif kind == 2 and isinstance(reply.body, bytes):
        reply.headers["Content-Length"] = str(max(0, len(reply.body) - rng.randint(1, 20)))
    elif kind == 3 and isinstance(reply.body, bytes):
        reply.headers["Content-Encoding"] = "gzip"
        reply.body = gzip.compress(reply.body) if rng.random() < 0.5 else b"\x1f\x8b" + reply.body[:30]
    elif kind == 4:
        reply.headers["Content-Length"] = str(rng.choice([1 << 40, 400 << 20]))


def _endless(rng, reply: Reply):
    reply.body = endless(rng.choice([b'{"00100010":{"vr":"PN","Value":[{"Alphabetic":"x"}]}},', b" " * 4096,
                                     b"\x00" * 4096]), b"[")


def _dribble(rng, reply: Reply):
    whole = reply.body if isinstance(reply.body, bytes) else b"[]"
    reply.body = lambda: (whole[i:i + 1] for i in range(len(whole)))
    reply.pause = 0.25


#: mutation name -> (weight, function(rng, reply, other archive's url))
MUTATIONS = {"json-value": (6, lambda rng, r, o: _json_edit(rng, r)),
             "json-delete": (3, lambda rng, r, o: _json_edit(rng, r, delete=True)),
             "text": (6, lambda rng, r, o: _text(rng, r)), "bytes": (5, lambda rng, r, o: _bytes(rng, r)),
             "status": (2, _status), "headers": (3, lambda rng, r, o: _headers(rng, r)),
             "endless": (1, lambda rng, r, o: _endless(rng, r)), "dribble": (0.3, lambda rng, r, o: _dribble(rng, r))}


def make_reply(seed: int, k: int, other: str) -> tuple[str, str, list[Reply]]:
    """``(name, operation, answers)`` of reply ``k`` of campaign ``seed``: every answer of the operation as it
    should be but one, mutated."""
    rng = random.Random(f"{seed}:{k}")
    op = rng.choice(sorted(OPERATIONS))
    answers = OPERATIONS[op]
    replies = [Reply(body(), headers=dict(headers)) for body, headers in answers]
    target = rng.randrange(len(replies))
    names = rng.choices(sorted(MUTATIONS), weights=[MUTATIONS[n][0] for n in sorted(MUTATIONS)],
                        k=rng.choice([1, 1, 2]))
    for name in names:
        if callable(replies[target].body) and name not in ("status", "headers"):
            continue
        MUTATIONS[name][1](rng, replies[target], other)
    return f"{'+'.join(names)} ({op}, answer {target})", op, replies


def _call(server: str, operation: str):
    """Run ``operation`` against ``server`` as ``volumen pacs`` would; what it would print."""
    import volumen.pacs as pacs

    if operation in ("find", "find-json"):
        found = pacs.find(server)
        if operation == "find-json":
            return json.dumps([{**s.__dict__, "modalities": list(s.modalities)} for s in found])
        return "\n".join("  ".join(row) for row in found.rows())
    if operation == "series":
        return "\n".join("  ".join(pacs.printable(v) for v in (s.number, s.modality, s.description, s.uid))
                         for s in pacs.series(server, STUDY))
    return str(pacs.retrieve(server, STUDY, SERIES))


def run_reply(archive: HostileArchive, server: str, operation: str, replies: list[Reply]) -> tuple[str, str]:
    """``(outcome, detail)`` of ``operation`` (``volumen.pacs``'s function behind the command) against
    ``archive`` answering ``replies`` in turn: ``ok``, ``refused`` (an ``ArchiveError`` whose message is one
    printable line: the command's one line and exit 1), ``crash`` (any other exception, or a message holding
    control characters), ``escape`` (a control character in what a table would print)."""
    from volumen.errors import ArchiveError

    queue = list(replies)
    archive.reply = lambda path: queue.pop(0) if len(queue) > 1 else queue[0]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")   # a warning would be printed: it quotes the server's values
            text = _call(server, operation)
    except ArchiveError as exc:
        message = str(exc)
        if not message.isprintable():
            return "crash", f"unprintable message {message[:100]!r}"
        return "refused", message[:160]
    except BaseException as exc:  # noqa: BLE001 - anything else escaping is what the fuzzer looks for
        return "crash", f"{type(exc).__name__}: {str(exc)[:100]!r}"
    if operation != "find-json" and any(not (c.isprintable() or c in "\n ") for c in text):
        return "escape", repr(text[:100])
    return "ok", ""


def timed(fn, *args) -> tuple[tuple[str, str], float]:
    t0 = time.perf_counter()
    result = fn(*args)
    return result, time.perf_counter() - t0
