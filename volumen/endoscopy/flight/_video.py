"""Writing frames to a video file: MP4 (H.264 through imageio's ffmpeg plugin) or GIF, chosen by suffix."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["VideoWriter", "VIDEO_SUFFIXES"]

VIDEO_SUFFIXES = (".mp4", ".gif")


class VideoWriter:
    """Append 8-bit RGB frames ``(H, W, 3)`` to ``path``; use as a context manager.

    Parameters
    ----------
    path : str or Path
        ``.mp4`` (H.264, yuv420p, needs ``imageio-ffmpeg``) or ``.gif`` (Pillow;
        frames are kept in memory until :meth:`close`).
    fps : float
        Frames per second.

    Notes
    -----
    H.264 in yuv420p needs even sizes: an odd width or height is padded by
    one black column or row. Pillow's GIF writer merges identical consecutive
    frames into one shown longer.
    """

    def __init__(self, path, fps: float = 25.0):
        self.path = Path(path)
        suffix = self.path.suffix.lower()
        if suffix not in VIDEO_SUFFIXES:
            raise ValueError(f"video file must end with one of {', '.join(VIDEO_SUFFIXES)}, got {self.path.name!r}")
        if not (np.isfinite(fps) and fps > 0):
            raise ValueError(f"fps must be > 0, got {fps}")
        self.fps = float(fps)
        self.suffix = suffix
        self.count = 0
        self._gif: list[np.ndarray] = []
        self._writer = None
        if suffix == ".mp4":
            import imageio.v2 as iio

            from ...errors import require

            require("imageio_ffmpeg", "writing MP4")
            self._writer = iio.get_writer(str(self.path), format="FFMPEG", mode="I", fps=self.fps, codec="libx264",
                                          pixelformat="yuv420p", macro_block_size=1, quality=8)

    def append(self, frame: np.ndarray) -> None:
        """Add one frame: uint8 ``(H, W, 3)`` (or ``(H, W, 4)``, alpha dropped)."""
        f = np.asarray(frame)
        if f.dtype != np.uint8 or f.ndim != 3 or f.shape[2] not in (3, 4):
            raise ValueError(f"frames must be uint8 (H, W, 3), got {f.dtype} {f.shape}")
        f = f[..., :3]
        if self.suffix == ".mp4":
            h, w = f.shape[:2]
            if h % 2 or w % 2:
                f = np.pad(f, ((0, h % 2), (0, w % 2), (0, 0)))
            self._writer.append_data(np.ascontiguousarray(f))
        else:
            self._gif.append(np.ascontiguousarray(f))
        self.count += 1

    def close(self) -> None:
        """Finish the file."""
        if self._writer is not None:
            self._writer.close()
            self._writer = None
        elif self._gif:
            from PIL import Image as PILImage

            ims = [PILImage.fromarray(f) for f in self._gif]
            ims[0].save(self.path, save_all=True, append_images=ims[1:], duration=int(round(1000 / self.fps)),
                        loop=0)
            self._gif = []

    def __enter__(self) -> VideoWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
