"""Plain data of volumen: volumes, slices and (later) cameras, lights and images. numpy only."""

from ._volume import Volume, axis_codes

__all__ = ["Volume", "axis_codes"]
