"""The app's background warm-up: after the first picture of a volume, other modes' kernels compile aside.

Each ray-casting mode and shading model has its own kernel, compiled on its first use (10-37 s each on 2 cores;
docs/design.md section 9): without this, the 3-D view waits that long the first time the user picks shadows.
After the first finished CPU ray-cast picture of a kind of volume (colour or not: every sample type reaches the
kernels as int16), :class:`Warmup` compiles the kernels of the modes and shading models in :data:`VARIANTS`
(the common ones: not path tracing, label maps or pre-integration, which compile on first use) with
``volumen.render.warm`` in one child process at low priority (niceness :data:`NICE`), which yields the cores to
the pictures being drawn; picking one of them later loads it from Numba's disk cache. Closing the window stops
the child, and the child dies with the app however it ends. Set ``VOLUMEN_WARM=0`` to turn it off (it then
compiles on first use).
"""

from __future__ import annotations

import os
import threading
from dataclasses import replace

from ..core import is_chunked
from ..render import resolve_device
from ..render._warm import COMMON_KERNELS
from ._view_picture import raycast_device

__all__ = ["Warmup", "VARIANTS", "NICE", "ENV", "variants"]

#: (mode, shading model) of every kernel warmed
VARIANTS = COMMON_KERNELS
#: added niceness of the child that compiles
NICE = 10
#: environment variable: ``0`` turns the warm-up off
ENV = "VOLUMEN_WARM"


def variants(job) -> list:
    """``(scene, camera)`` of each of :data:`VARIANTS` but the job's own, on the job's volume (no label map)."""
    scene = replace(job.scene, labels=None)
    own = (scene.mode, scene.shading.mode)
    return [(replace(scene, mode=m, shading=replace(scene.shading, mode=s)), job.camera)
            for m, s in VARIANTS if (m, s) != own]


class Warmup:
    """Warms the other kernels once per kind of volume, one warm-up at a time (see the module docstring)."""

    def __init__(self):
        self._lock = threading.Lock()
        self._cancel = threading.Event()
        self._thread: threading.Thread | None = None
        self._kinds: set = set()
        self.finished: dict = {}

    def _wanted(self, job) -> tuple | None:
        """The job's kind of volume, when its picture is drawn by the CPU's ray caster and warming is on."""
        vol = job.scene.volume
        if (os.environ.get(ENV, "1").strip() == "0" or job.technique.name != "raycast" or vol is None
                or is_chunked(vol.data) or resolve_device(raycast_device(job), "raycast") != "cpu"):
            return None
        return vol.is_color

    def after(self, job) -> bool:
        """Called after a finished picture of ``job``: start warming when it is the first CPU ray-cast picture of
        its kind of volume; whether it started (never raises: a warm-up is an extra)."""
        try:
            kind = self._wanted(job)
            with self._lock:
                if kind is None or kind in self._kinds or self.running or self._cancel.is_set():
                    return False
                self._kinds.add(kind)
                self._thread = threading.Thread(target=self._run, args=(variants(job),), name="volumen-warmup",
                                                daemon=True)
                self._thread.start()
            return True
        except Exception:  # noqa: BLE001 - the picture is drawn; its kernels then compile on first use
            return False

    def _run(self, jobs) -> None:
        from ..render import warm

        self.finished.update(warm(jobs, workers=1, nice=NICE, cancel=self._cancel))

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop the child (a kernel half compiled is not cached) and wait for the thread; none starts after."""
        with self._lock:
            self._cancel.set()
            thread = self._thread
        if thread is not None:
            thread.join(timeout)
