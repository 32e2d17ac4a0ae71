"""JSON round trip for the settings dataclasses (docs/design.md section 2: settings are data).

Every dataclass that decides a picture (Camera, TransferFunction, Light,
Shading, Sampling, Clipping, ...) inherits :class:`JsonData`: ``to_dict``
gives plain JSON types (tuples become lists), ``from_dict`` refuses unknown
keys with a message listing the valid ones, and the constructor validates the
values again, so a file edited by hand cannot smuggle in a bad setting.
"""

from __future__ import annotations

import json
from dataclasses import asdict, fields

import numpy as np

__all__ = ["JsonData", "_choice", "_vec", "_nonneg"]


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


# validators shared by the settings dataclasses (their error messages name the field and what it takes)
def _choice(name: str, value, choices) -> None:
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}; got {value!r}")


def _vec(name: str, v, n: int = 3, unit: bool = False) -> tuple[float, ...]:
    a = np.asarray(v, dtype=float).ravel()
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be {n} finite numbers, got {v!r}")
    if unit and np.linalg.norm(a) < 1e-12:  # kept as given (exact JSON round trip); renderers normalize
        raise ValueError(f"{name} must not be the zero vector")
    return tuple(float(x) for x in a)


def _nonneg(name: str, v) -> float:
    v = float(v)
    if not (np.isfinite(v) and v >= 0):
        raise ValueError(f"{name} must be a finite number >= 0, got {v}")
    return v
