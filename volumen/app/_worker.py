"""The render worker: a thread that turns :class:`FrameJob` requests into frames, newest first.

The interface thread only posts requests (:meth:`RenderWorker.submit`) and
receives finished :class:`~volumen.app._view_picture.ViewPicture` objects through the
``frame_ready`` signal (queued into the interface thread), so it never waits
on a renderer. Only the newest request is kept: a request posted while a
picture is being made replaces any older one still waiting.

* ``interactive=True`` (the user drags): rendered at a reduced viewport --
  half the size, or a quarter when half took longer than
  :attr:`RenderWorker.budget` seconds -- and upscaled (``final`` False);
* otherwise the full picture (:func:`~volumen.app._view_picture.progressive_frames`;
  path tracing refines while idle and stops as soon as a new request comes); after the first one of a kind of
  volume, the other modes' kernels compile in a background process (:class:`~volumen.app._warmup.Warmup`);
* either way, while the CPU kernel a picture needs is not compiled yet, its compile starts in a child process
  and OpenGL draws a stand-in at a reduced viewport (``volumen.render._standin``); the picture is drawn on the
  CPU once the kernel is in the cache, unless a newer request came first.

OpenGL techniques (texture slicing, meshes) run on the process's one OpenGL
thread (``_view_picture.on_gl_thread``); the worker probes once whether they are
available (``raster_status``).
"""

from __future__ import annotations

import threading
import time
import traceback
from dataclasses import replace

from PySide6.QtCore import QObject, Signal

from ..render import _standin
from ._view_picture import FrameJob, progressive_frames, raycast_device, render_frame
from ._warmup import Warmup

__all__ = ["RenderWorker"]


class RenderWorker(QObject):
    """Renders in a background thread; see the module docstring.

    Signals
    -------
    frame_ready(ViewPicture)
    failed(int token, str message)
    raster_status(bool available, str reason)
    """

    frame_ready = Signal(object)
    failed = Signal(int, str)
    raster_status = Signal(bool, str)

    def __init__(self, parent=None, *, budget: float = 0.06):
        super().__init__(parent)
        self.budget = float(budget)
        self.fraction = 0.5
        self._cond = threading.Condition()
        self._pending: tuple[FrameJob, bool] | None = None
        self._stop = False
        self._busy = False
        self._thread = threading.Thread(target=self._loop, name="volumen-render", daemon=True)
        self.warmup = Warmup()

    def start(self) -> None:
        """Start the thread: call it once the signals are connected (its first act, the OpenGL probe, emits
        :attr:`raster_status`, which a later connection would miss)."""
        self._thread.start()

    # -- interface thread -------------------------------------------------------
    def submit(self, job: FrameJob, *, interactive: bool = False) -> None:
        """Ask for a picture of ``job`` (replacing any request not started yet)."""
        with self._cond:
            self._pending = (job, bool(interactive))
            self._cond.notify()

    @property
    def idle(self) -> bool:
        """True when nothing is being rendered or waiting."""
        with self._cond:
            return self._pending is None and not self._busy

    def stop(self, timeout: float = 10.0) -> None:
        """End the thread (after the picture in progress). A picture still in progress after ``timeout`` (a
        first picture compiling its kernels) finishes unseen: nothing is emitted after ``stop``, when the
        window that owns this worker may be gone."""
        with self._cond:
            self._stop = True
            self._pending = None
            self._cond.notify()
        self.warmup.stop()
        self._thread.join(timeout)

    # -- worker thread ----------------------------------------------------------
    def _emit(self, signal, *args) -> bool:
        """``signal.emit(*args)`` unless stopped; False when not emitted (stopped, or Qt deleted this object
        while the picture was made: "Signal source has been deleted")."""
        with self._cond:
            if self._stop:
                return False
        try:
            signal.emit(*args)
        except RuntimeError:
            return False
        return True

    def _has_pending(self) -> bool:
        with self._cond:
            return self._pending is not None or self._stop

    def _probe_raster(self) -> None:
        from ._view_picture import on_gl_thread

        def probe():
            from ..render.raster import gl_renderer

            return gl_renderer()[0]

        try:
            renderer = on_gl_thread(probe)
        except Exception as exc:  # noqa: BLE001 - any failure means: no OpenGL here
            self._emit(self.raster_status, False, f"OpenGL is not available: {type(exc).__name__}: {exc}")
        else:
            self._emit(self.raster_status, True, renderer)

    def _stand_in(self, job: FrameJob) -> threading.Event | None:
        """While ``job``'s CPU kernel compiles aside: emit OpenGL's stand-in and return the Event set when the
        kernel is compiled; None when the CPU draws now (or OpenGL failed: then the CPU draws, compiling)."""
        try:
            if job.mesh is not None and job.mesh_display == "instead":
                return None
            compiled = _standin.compiling(job.scene, job.camera, raycast_device(job), job.technique)
            if compiled is None:
                return None
            frame = render_frame(replace(job, device="gl"), _standin.drawn_at(self.fraction), final=False)
        except Exception:  # noqa: BLE001 - a stand-in is an extra: the CPU draws the picture (compiling)
            return None
        frame.stats = dict(frame.stats, stand_in=True)
        self._emit(self.frame_ready, frame)
        return compiled

    def _again_when(self, compiled: threading.Event, job: FrameJob, interactive: bool) -> None:
        """Post ``job`` again once ``compiled`` is set, unless a newer request (or stop) comes first."""
        with self._cond:
            while not compiled.is_set() and self._pending is None and not self._stop:
                self._cond.wait(0.1)
            if self._pending is None and not self._stop:
                self._pending = (job, interactive)

    def _loop(self) -> None:
        self._probe_raster()
        while True:
            with self._cond:
                while self._pending is None and not self._stop:
                    self._cond.wait()
                if self._stop:
                    return
                job, interactive = self._pending
                self._pending = None
                self._busy = True
            try:
                if (compiled := self._stand_in(job)) is not None:
                    self._again_when(compiled, job, interactive)
                elif interactive:
                    t = time.perf_counter()
                    frame = render_frame(job, self.fraction, final=False)
                    dt = time.perf_counter() - t
                    if dt > self.budget and self.fraction > 0.25:
                        self.fraction = 0.25
                    elif dt < 0.3 * self.budget and self.fraction < 0.5:
                        self.fraction = 0.5
                    self._emit(self.frame_ready, frame)
                else:
                    for frame in progressive_frames(job, cancelled=self._has_pending):
                        if not self._emit(self.frame_ready, frame):
                            break
                    else:
                        self.warmup.after(job)
            except Exception as exc:  # noqa: BLE001 - reported to the interface, never kills the thread
                msg = f"{type(exc).__name__}: {exc}"
                if not isinstance(exc, (ValueError, RuntimeError)):
                    msg += "\n" + traceback.format_exc(limit=4)
                self._emit(self.failed, job.token, msg)
            finally:
                with self._cond:
                    self._busy = False
