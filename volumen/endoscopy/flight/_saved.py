"""A saved flight: the keyframes, the endoscope's settings and the centerline, in one JSON file.

``volumen fly --save-path FILE`` writes it; :meth:`Flight.load` reads it back on
a volume, and ``flight.endoscope.render(pose, size)`` then draws every frame of
``flight.path.play(fps)`` exactly as the command did (bit for bit: the same
settings, the same poses, a jitter that depends on the pixel only).

A flight made from a lumen (grown, or a segmentation) holds the lumen too
(:class:`LumenWall`: its estimate and its mask, packed): the endoscope draws the
field made from them, and loading the flight makes it again from the scan.

A plain keyframe path file (:meth:`KeyframePath.save`) loads too, with the
default endoscope.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from ..lumen._drawn_wall import LumenWall
from ..path._centerline import Centerline
from ..path._keyframes import KeyframePath
from ._endoscope import Endoscope

__all__ = ["Flight"]

FORMAT = "volumen-flight"


@dataclass(frozen=True)
class Flight:
    """What a flythrough needs besides the volume.

    Attributes
    ----------
    path : KeyframePath
        The camera's keyframes and speed (mm/s).
    endoscope : Endoscope
        How frames are drawn (on the volume given to :meth:`load`).
    centerline : Centerline or None
        The lumen's centerline the path was made from (curved planar reformation uses it).
    lumen : LumenWall or None
        The lumen and its estimate; the endoscope's volume is then the field they make
        (:meth:`LumenWall.volume`), not the scan.
    """

    path: KeyframePath
    endoscope: Endoscope
    centerline: Centerline | None = None
    lumen: LumenWall | None = None

    def to_dict(self) -> dict:
        """``{"format", "version", "path", "endoscope", "centerline", "lumen"}``, JSON-ready."""
        return {"format": FORMAT, "version": 1, "path": self.path.to_dict(), "endoscope": self.endoscope.to_dict(),
                "centerline": None if self.centerline is None else self.centerline.to_dict(),
                "lumen": None if self.lumen is None else self.lumen.to_dict()}

    def save(self, file) -> None:
        """Write the flight as JSON (to a temporary file first, so a failure leaves no half-written file)."""
        file = Path(file)
        tmp = file.with_name(file.name + ".part")
        tmp.write_text(json.dumps(self.to_dict(), indent=1))
        tmp.replace(file)

    @classmethod
    def from_dict(cls, d: dict, volume) -> Flight:
        if d.get("format") != FORMAT:  # a bare keyframe path
            return cls(KeyframePath.from_dict(d), Endoscope(volume=volume))
        extra = set(d) - {"format", "version", "path", "endoscope", "centerline", "lumen"}
        if extra:
            raise ValueError(f"unknown flight fields {sorted(extra)}")
        cl = d.get("centerline")
        lumen = None if d.get("lumen") is None else LumenWall.from_dict(d["lumen"], volume.shape)
        drawn = volume if lumen is None else lumen.volume(volume)
        return cls(KeyframePath.from_dict(d["path"]), Endoscope.from_dict(d["endoscope"], drawn),
                   None if cl is None else Centerline.from_dict(cl), lumen)

    @classmethod
    def load(cls, file, volume) -> Flight:
        """Read a flight (or a keyframe path) written by :meth:`save`; a bad file raises ValueError naming it."""
        try:
            return cls.from_dict(json.loads(Path(file).read_text()), volume)
        except (OSError, json.JSONDecodeError, TypeError, KeyError, ValueError) as exc:
            raise ValueError(f"{file}: not a volumen flight: {exc}") from None
