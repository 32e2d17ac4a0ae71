"""The render loop of the notebook view: one background thread, newest request wins, refinement when idle.

The kernel's thread only files requests (:meth:`RenderLoop.request`) and never waits for a picture,
so the notebook stays responsive while a frame is computed. A request made while the user drags
asks for a reduced viewport (``fraction`` < 1, as the desktop app's worker does); once no new
request has come for ``refine_after`` seconds the loop renders the same state at full size. While a
``stand_in`` callable offers a frame (OpenGL's, while the CPU kernel compiles aside: ``volumen.render._standin``)
that frame is delivered as a reduced one, and the request is drawn again once its kernel is compiled, unless a
newer request came first.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

__all__ = ["RenderLoop", "Request", "REDUCED_FRACTION", "REFINE_AFTER"]

#: side ratio of the viewport while dragging (the desktop app's worker starts at one half too)
REDUCED_FRACTION = 0.5
#: seconds without a new request before the full-size picture is rendered (the app waits 150 ms)
REFINE_AFTER = 0.15


@dataclass(frozen=True)
class Request:
    """What to draw: the ``state`` passed to the draw function, at ``fraction`` of the size; ``token`` counts."""

    state: Any
    fraction: float
    token: int


class RenderLoop:
    """Render requests on a daemon thread.

    Parameters
    ----------
    draw : callable(state, fraction) -> frame
        Runs on the loop's thread.
    deliver : callable(frame, request)
        Called on the loop's thread with each finished frame (``request.fraction == 1``: the final one).
    refine_after : float, seconds
    stand_in : callable(state, fraction) -> (frame, fraction, threading.Event) or None, optional
        Asked before each draw: a stand-in frame, the fraction it was drawn at, and the Event set when ``draw``
        can run without waiting; None: ``draw`` runs now.
    """

    def __init__(self, draw: Callable, deliver: Callable, refine_after: float = REFINE_AFTER,
                 stand_in: Callable | None = None):
        self._draw, self._deliver, self.refine_after = draw, deliver, float(refine_after)
        self._stand_in = stand_in
        self._cond = threading.Condition()
        self._pending: Request | None = None
        self._token = 0
        self._done = 0          # token of the newest final frame delivered
        self._busy = False
        self._stop = False
        self.error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="volumen-notebook-render", daemon=True)
        self._thread.start()

    def request(self, state, fraction: float = 1.0) -> int:
        """File a request (replacing any not yet started); returns its token."""
        with self._cond:
            self._token += 1
            self._pending = Request(state, float(fraction), self._token)
            self._cond.notify_all()
            return self._token

    def wait(self, timeout: float = 60.0) -> bool:
        """Block until the newest request's final frame is delivered (tests, scripts); False on timeout."""
        end = time.monotonic() + timeout
        with self._cond:
            while self._done < self._token or self._pending is not None or self._busy:
                left = end - time.monotonic()
                if left <= 0 or self._stop:
                    return False
                self._cond.wait(left)
        if self.error is not None:
            raise self.error
        return True

    def close(self) -> None:
        with self._cond:
            self._stop = True
            self._cond.notify_all()

    def _next(self) -> Request | None:
        with self._cond:
            while self._pending is None and not self._stop:
                self._cond.wait()
            req, self._pending = self._pending, None
            self._busy = req is not None
            return req

    def _again_when(self, ready, req: Request) -> None:
        """(Holding the lock) file ``req`` again once ``ready`` is set, unless a newer request or close comes."""
        while not ready.is_set() and self._pending is None and not self._stop:
            self._cond.wait(0.1)
        if self._pending is None and not self._stop:
            self._pending = req
        self._cond.notify_all()

    def _run(self) -> None:
        while (req := self._next()) is not None:
            shown = None
            try:
                shown = self._stand_in(req.state, req.fraction) if self._stand_in is not None else None
                if shown is None:
                    self._deliver(self._draw(req.state, req.fraction), req)
                else:
                    self._deliver(shown[0], replace(req, fraction=shown[1]))
                self.error = None
            except Exception as exc:  # noqa: BLE001 - the loop must survive a bad setting; wait() re-raises it
                self.error = exc
            with self._cond:
                self._busy = False
                if shown is not None and self.error is None:
                    self._again_when(shown[2], req)
                elif req.fraction >= 1.0 or self.error is not None:
                    self._done = max(self._done, req.token)
                elif self._pending is None:  # refine once no newer request comes in time
                    self._cond.wait(self.refine_after)
                    if self._pending is None and not self._stop:
                        self._pending = replace(req, fraction=1.0)
                self._cond.notify_all()
