"""Screenshots: the whole window as shown, or the 3D view rendered again at any size.

The 3D screenshot uses the same :func:`~volumen.app._view_picture.render_frame` as
the view (full quality, path tracing to its full sample count), so the saved
picture is the view's picture at another size.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtWidgets import QWidget

__all__ = ["save_widget", "render_view_picture", "save_rgb"]


def save_widget(widget: QWidget, path) -> Path:
    """Save what ``widget`` shows (``QWidget.grab``) as PNG; raises OSError when it cannot be written."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not widget.grab().save(str(path)):
        raise OSError(f"could not write the screenshot {path}")
    return path


def render_view_picture(job, size: tuple[int, int]) -> np.ndarray:
    """The 3D view's ``FrameJob`` rendered at ``size = (width, height)``: uint8 ``(H, W, 3)``."""
    from ._view_picture import progressive_frames, with_size

    *_, last = progressive_frames(with_size(job, size), batch=16)  # the refined frame is the last one
    return last.rgb


def save_rgb(rgb: np.ndarray, path) -> Path:
    """Write a uint8 ``(H, W, 3)`` picture as PNG (Pillow)."""
    from PIL import Image as PILImage

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    PILImage.fromarray(np.ascontiguousarray(rgb)).save(path)
    return path
