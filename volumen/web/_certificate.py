"""The host names a server certificate is for: the DNS names of its Subject Alternative Name extension.

``volumen serve --certfile`` adds them to the names a request's ``Host`` may carry (``_requests.host_allowed``).
Read here from the certificate's DER bytes (the standard library loads a certificate into a context but has no
public reader of its fields, and ``cryptography`` is not a dependency): the extension is found by its OID
(2.5.29.17) and its ``dNSName`` entries (context tag ``[2]``) are listed.
"""

from __future__ import annotations

import base64
import re
from pathlib import Path

__all__ = ["certificate_names"]

_SAN_OID = bytes.fromhex("0603551d11")   # OBJECT IDENTIFIER 2.5.29.17
_PEM = re.compile(rb"-----BEGIN CERTIFICATE-----(.+?)-----END CERTIFICATE-----", re.DOTALL)


def _length(der: bytes, i: int) -> tuple[int, int]:
    """``(length, index of the content)`` of the DER element whose length byte is at ``i``."""
    first = der[i]
    if first < 0x80:
        return first, i + 1
    n = first & 0x7F
    return int.from_bytes(der[i + 1:i + 1 + n], "big"), i + 1 + n


def _element(der: bytes, i: int) -> tuple[int, bytes, int]:
    """``(tag, content, index after it)`` of the DER element at ``i``."""
    n, start = _length(der, i + 1)
    return der[i], der[start:start + n], start + n


def _san_names(der: bytes) -> list[str]:
    at = der.find(_SAN_OID)
    if at < 0:
        return []
    i = at + len(_SAN_OID)
    tag, content, i = _element(der, i)
    if tag == 0x01:   # the extension's 'critical' flag
        tag, content, i = _element(der, i)
    if tag != 0x04:   # OCTET STRING holding the GeneralNames
        return []
    tag, names, _ = _element(content, 0)
    out, j = [], 0
    while tag == 0x30 and j < len(names):
        kind, value, j = _element(names, j)
        if kind == 0x82:
            out.append(value.decode("ascii", "replace"))
    return out


def certificate_names(path) -> tuple[str, ...]:
    """The DNS names of the first certificate of the PEM file ``path`` (empty when it has none or does not read)."""
    try:
        m = _PEM.search(Path(path).read_bytes())
        return tuple(_san_names(base64.b64decode(b"".join(m.group(1).split())))) if m else ()
    except (OSError, ValueError, IndexError):
        return ()
