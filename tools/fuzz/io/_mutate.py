"""Mutations: generic byte edits and field edits of text headers (NRRD, MetaImage, VTK).

Every mutation is a function ``(rng, data, ctx) -> (bytes, description)``; ``ctx``
carries the paths a header may be pointed at (the canary outside the mutant's
folder, relative and absolute). Byte edits prefer the header (the first bytes),
where a flipped bit changes meaning rather than one voxel.
"""

from __future__ import annotations

import random
import re
from dataclasses import dataclass

__all__ = ["Context", "GENERIC", "text_edit", "INTERESTING_NUMBERS"]

INTERESTING_NUMBERS = ("0", "-1", "1", "2", "-100", "255", "65536", "2147483647", "2147483648", "-2147483649",
                       "4294967296", "9223372036854775807", "18446744073709551616", "99999999999999999999999",
                       "100000000", "1e308", "-1e308", "1e-320", "nan", "inf", "-inf", "0x10", "1.5", "", "abc")
_INTERESTING_BYTES = (b"\x00", b"\xff", b"\x7f", b"\x80", b"\x00\x00\x00\x80", b"\xff\xff\xff\x7f",
                      b"\x00\x00\x00\x00\x00\x00\xf0\x7f", b"\xff\xff\xff\xff\xff\xff\xff\xff", b"\n", b"%", b".")


@dataclass(frozen=True)
class Context:
    outside_rel: str  # a file outside the mutant's folder, relative to it
    outside_abs: str  # the same file, absolute

    def paths(self) -> tuple[str, ...]:
        return (self.outside_rel, self.outside_abs, "/etc/passwd", "..", ".", "", "missing.raw",
                "../" * 12 + "etc/hostname", "%d 1 3 0", "x%03d.raw 0 100000000 1", "%s 1 2 1", "%n%n%n 1 2 1",
                self.outside_rel.replace("canary.raw", "%d.raw") + " 1 2 1", "LIST", "LIST 9", "LIST -1")


def _where(rng: random.Random, n: int) -> int:
    """An offset, 70% of the time in the first 1 KiB."""
    if n == 0:
        return 0
    return rng.randrange(min(n, 1024)) if rng.random() < 0.7 else rng.randrange(n)


def bit_flips(rng, data, ctx):
    b = bytearray(data)
    k = rng.choice((1, 1, 2, 4, 8, 32))
    for _ in range(k if b else 0):
        i = _where(rng, len(b))
        b[i] ^= 1 << rng.randrange(8)
    return bytes(b), f"{k} bit flips"


def overwrite(rng, data, ctx):
    b = bytearray(data)
    i = _where(rng, len(b))
    chunk = rng.choice(_INTERESTING_BYTES) if rng.random() < 0.6 else rng.randbytes(rng.randint(1, 16))
    b[i:i + len(chunk)] = chunk
    return bytes(b), f"overwrite {len(chunk)} bytes at {i}"


def truncate(rng, data, ctx):
    n = _where(rng, len(data)) if rng.random() < 0.5 else rng.randrange(len(data) + 1)
    return data[:n], f"truncate to {n} bytes"


def splice(rng, data, ctx):
    """Delete or repeat a chunk."""
    i = _where(rng, len(data))
    k = rng.randint(1, 64)
    if rng.random() < 0.5:
        return data[:i] + data[i + k:], f"delete {k} bytes at {i}"
    return data[:i] + data[i:i + k] * rng.randint(2, 50) + data[i + k:], f"repeat {k} bytes at {i}"


GENERIC = (bit_flips, overwrite, truncate, splice)


# -- text headers -------------------------------------------------------------
_KEYS = {
    "nrrd": {
        "sizes": ("100000 100000 100000", "-1 6 5", "0 0 0", "7 6", "1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1",
                  "99999999999999999999 1 1", "nan 1 1", "7 6 5 1000000000", "2147483648 2 1"),
        "dimension": ("-1", "0", "1", "2", "4", "17", "100", "99999999"),
        "type": ("float", "double", "int8", "uint64", "block", "foo", "", "unsigned long long int"),
        "encoding": ("raw", "gzip", "bzip2", "ascii", "hex", "zrl", "foo", "txt"),
        "line skip": ("100000000", "-1", "5", "99999999999999999999"),
        "byte skip": ("-1", "100000000", "-5", "3", "99999999999999999999"),
        "endian": ("big", "little", "middle", ""),
        "space directions": ("(0,0,0) (0,0,0) (0,0,0)", "(nan,0,0) (0,1,0) (0,0,1)",
                             "(1e308,0,0) (0,1e308,0) (0,0,1e308)", "none none none",
                             "(1,0) (0,1)", "(1,0,0) (0,1,0)", "((1,0,0)", "(1,0,0) (2,0,0) (0,0,1)"),
        "space origin": ("(nan,nan,nan)", "(1e308,1e308,1e308)", "(1,2)", "((", "(inf,0,0)"),
        "space": ("RAS", "foo", "scanner-xyz", "right-anterior-superior-time", ""),
        "space dimension": ("2", "3", "100", "-1"),
        "spacings": ("0 0 0", "-1 1 1", "nan nan nan", "1e308 1e308 1e308", "1 1"),
        "kinds": ("domain domain domain", "list list list", "RGB-color domain domain", "foo", ""),
        "block size": ("0", "-1", "100000000"),
        "axis mins": ("nan nan nan", "1e308 -1e308 0", "1"),
        "centerings": ("cell cell cell", "node", "???"),
        "volumen": ("{}", "{\"format\":\"volumen-geometry\",\"version\":1,\"spacing\":[0,0,0],"
                          "\"affine\":[[0,0,0,0],[0,0,0,0],[0,0,0,0],[0,0,0,1]]}", "[[[[[[[[[[", "null"),
    },
    "metaimage": {
        "NDims": ("-1", "0", "1", "2", "4", "100", "1000000", "abc", "99999999999999999999"),
        "DimSize": ("100000 100000 100000", "-1 6 5", "0 0 0", "7 6", "7 6 5 4", "99999999999999999999 1 1",
                    "2147483648 2 1", "7.5 6 5", "nan"),
        "ElementType": ("MET_FLOAT", "MET_DOUBLE", "MET_UCHAR", "MET_ULONG_LONG", "MET_STRING", "MET_FOO", "",
                        "MET_UCHAR_ARRAY", "MET_OTHER"),
        "ElementNumberOfChannels": ("0", "-1", "3", "100000000", "abc"),
        "HeaderSize": ("-1", "100000000", "5", "-5", "abc"),
        "CompressedData": ("True", "False", "maybe"),
        "CompressedDataSize": ("0", "-1", "1", "99999999999999999999"),
        "ElementSpacing": ("0 0 0", "-1 1 1", "nan nan nan", "1e308 1e308 1e308", "1 1", "inf 1 1"),
        "ElementSize": ("0 0 0", "-1 1 1"),
        "Offset": ("nan nan nan", "1e308 1e308 1e308", "1 2", "abc"),
        "TransformMatrix": ("0 0 0 0 0 0 0 0 0", "1 2 3", "nan 0 0 0 1 0 0 0 1", "1 0 0 1 0 0 0 0 1", ""),
        "BinaryDataByteOrderMSB": ("True", "False", "maybe"),
        "ElementByteOrderMSB": ("True", "False"),
        "BinaryData": ("False", "True"),
        "ObjectType": ("Mesh", "Image", ""),
        "ElementMin": ("nan",),
        "Volumen": ("{}", "[[[[[[[[", "null"),
    },
    "vtk": {
        "DIMENSIONS": ("100000 100000 100000", "-1 6 5", "0 0 0", "7 6", "2147483648 2 1", "7 6 5 4"),
        "SPACING": ("0 0 0", "-1 1 1", "nan nan nan", "1e308 1e308 1e308", "1 1"),
        "ORIGIN": ("nan 0 0", "1e308 1e308 1e308", "1"),
        "POINT_DATA": ("-1", "1000000000000", "0", "210000000000000000000000"),
        "SCALARS": ("density float 100000000", "density foo", "density short -1", "d float 0", "d double 4",
                    "density", "d unsigned_char 99999999999999999999"),
        "LOOKUP_TABLE": ("default", "", "other 5"),
        "DATASET": ("POLYDATA", "STRUCTURED_POINTS", "RECTILINEAR_GRID", ""),
    },
}
_DATA_FILE_KEYS = {"nrrd": "data file", "metaimage": "ElementDataFile"}
_SEP = {"nrrd": ": ", "metaimage": " = ", "vtk": " "}


def _header_span(kind: str, text: str) -> int:
    """Length of the header part of a text-header file (latin-1 decoded)."""
    if kind == "nrrd":
        end = text.find("\n\n")
        return len(text) if end < 0 else end + 1
    if kind == "metaimage":
        m = re.search(r"ElementDataFile[^\n]*\n", text)
        return len(text) if m is None else m.end()
    m = re.search(r"LOOKUP_TABLE[^\n]*\n", text)
    return len(text) if m is None else m.end()


def _split(kind: str, line: str) -> tuple[str, str]:
    if kind == "nrrd":
        key, _sep, value = line.partition(":")
        return key, value.lstrip("=").strip()
    if kind == "metaimage":
        key, _sep, value = line.partition("=")
        return key.strip(), value.strip()
    key, _sep, value = line.partition(" ")
    return key, value


def text_edit(kind: str):
    """A mutation editing one header line of a ``kind`` ("nrrd", "metaimage", "vtk") header."""

    def edit(rng: random.Random, data: bytes, ctx: Context):
        text = data.decode("latin-1")
        span = _header_span(kind, text)
        lines, body = text[:span].split("\n"), text[span:]
        keys = _KEYS[kind]
        op = rng.random()
        if op < 0.2 and kind in _DATA_FILE_KEYS:
            key, value = _DATA_FILE_KEYS[kind], rng.choice(ctx.paths())
        elif op < 0.75:
            key = rng.choice(list(keys))
            value = rng.choice(keys[key]) if rng.random() < 0.7 else rng.choice(INTERESTING_NUMBERS)
        else:
            i = rng.randrange(1, max(len(lines) - 1, 2))
            if i >= len(lines):
                return data, "no header line"
            how = rng.choice(("delete", "duplicate", "number"))
            if how == "delete":
                del lines[i]
            elif how == "duplicate":
                lines.insert(i, lines[i])
            else:
                key, value = _split(kind, lines[i])
                tokens = value.split() or [""]
                tokens[rng.randrange(len(tokens))] = rng.choice(INTERESTING_NUMBERS)
                lines[i] = key + _SEP[kind] + " ".join(tokens)
            return ("\n".join(lines) + body).encode("latin-1"), f"{how} header line {i}"
        for i, line in enumerate(lines):
            if _split(kind, line)[0].strip().lower() == key.lower():
                lines[i] = key + _SEP[kind] + value
                break
        else:
            lines.insert(max(len(lines) - 2, 1), key + _SEP[kind] + value)
        return ("\n".join(lines) + body).encode("latin-1"), f"set {key!r} to {value[:60]!r}"

    edit.__name__ = f"{kind}_field"
    return edit
