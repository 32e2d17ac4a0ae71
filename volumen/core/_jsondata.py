"""JSON round trip for the settings dataclasses (DESIGN.md section 2: settings are data).

Every dataclass that decides a picture (Camera, TransferFunction, Light,
Shading, Sampling, Clipping, ...) inherits :class:`JsonData`: ``to_dict``
gives plain JSON types (tuples become lists), ``from_dict`` refuses unknown
keys with a message listing the valid ones, and the constructor validates the
values again, so a file edited by hand cannot smuggle in a bad setting.
"""

from __future__ import annotations

import json
from dataclasses import asdict, fields

__all__ = ["JsonData"]


class JsonData:
    """Mixin for dataclasses: ``to_dict``/``from_dict``/``to_json``/``from_json``."""

    def to_dict(self) -> dict:
        """Plain JSON-ready dict (lists for tuples, nested dataclasses as dicts)."""
        return json.loads(json.dumps(asdict(self)))

    @classmethod
    def from_dict(cls, d: dict):
        """Inverse of :meth:`to_dict`; unknown keys raise ValueError naming the valid ones."""
        known = {f.name for f in fields(cls)}
        extra = set(d) - known
        if extra:
            raise ValueError(f"unknown {cls.__name__} fields {sorted(extra)}; valid: {sorted(known)}")
        return cls(**d)

    def to_json(self) -> str:
        return json.dumps(self.to_dict())

    @classmethod
    def from_json(cls, text: str):
        return cls.from_dict(json.loads(text))
