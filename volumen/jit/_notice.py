"""One line when a command starts compiling volumen's kernels, so a first picture's wait is not a silent one.

Numba compiles a kernel for this machine on its first use and keeps it in its disk cache; a cold ray caster or
path tracer takes from a few seconds to about a minute, during which a command printed nothing. :func:`announce`
registers a listener on Numba's ``numba:compile`` event (fired only when a kernel is compiled, not when it is
loaded from the cache) that writes one line, on a terminal, the first time one of volumen's own kernels starts
compiling. The command line installs it for the sub-commands that draw (``volumen.cli.COMPILING``); the
library itself prints nothing.
"""

from __future__ import annotations

import sys

from numba.core import event

__all__ = ["announce", "CompileNotice", "MESSAGE"]

MESSAGE = "compiling volumen's kernels for this machine (first use of this mode: up to a minute; cached after)"


class CompileNotice(event.Listener):
    """Writes :data:`MESSAGE` to ``stream`` when the first of volumen's kernels starts compiling in this process
    (``stream`` None: to stderr, and only when it is a terminal, as a progress bar would)."""

    def __init__(self, stream=None):
        self.stream = stream
        self.said = False

    def on_start(self, event) -> None:
        dispatcher = (event.data or {}).get("dispatcher")
        module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
        if self.said or not module.startswith("volumen."):
            return
        self.said = True
        stream = self.stream or sys.stderr
        if self.stream is not None or stream.isatty():
            print(MESSAGE + " ...", file=stream, flush=True)

    def on_end(self, event) -> None:
        pass


_installed: list[CompileNotice] = []


def announce(stream=None) -> CompileNotice:
    """Register a :class:`CompileNotice` for this process's compilations (once for stderr, however often it is
    called: the command line calls it per command); returns it."""
    if stream is None and _installed:
        return _installed[0]
    notice = CompileNotice(stream)
    event.register("numba:compile", notice)
    if stream is None:
        _installed.append(notice)
    return notice
