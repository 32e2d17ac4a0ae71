"""One compilation per kernel across the suite's worker processes (pytest-xdist).

Numba caches compiled kernels on disk (``cache=True``), but two workers that first call the same kernel at the
same time both compile it: on a cold checkout most of the suite's time is compilation, and the two workers
compiled largely the same kernels side by side. Here each cached dispatcher's ``compile(sig)`` first takes an
inter-process file lock named after (source file, function, signature); the second worker waits for the first,
then finds the kernel in Numba's disk cache (``compile`` looks there before compiling) and loads it.

Lock order follows the call graph (a kernel's compilation compiles its callees, never its callers), so two
workers cannot wait for each other; within a worker the file lock is taken under Numba's own compiler lock, so
two threads of one process cannot either. A lock not obtained within :data:`PATIENCE` seconds is given up and the
kernel compiled as before; dispatchers without a disk cache are not locked at all. Test infrastructure only:
volumen itself does not depend on it.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import tempfile
import time
from pathlib import Path

PATIENCE = 900.0  # seconds: longer than any single compilation seen (the path tracer: about 170 s under load)
POLL = 0.05


def _lock_dir() -> Path:
    d = Path(tempfile.gettempdir()) / f"volumen-compile-locks-{os.getuid()}"
    d.mkdir(exist_ok=True)
    return d


def _acquire(path: Path):
    fd = os.open(path, os.O_CREAT | os.O_RDWR, 0o600)
    deadline = time.monotonic() + PATIENCE
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return fd
        except BlockingIOError:
            if time.monotonic() > deadline:
                os.close(fd)
                return None
            time.sleep(POLL)


def _log(key: str, waited: float, took: float) -> None:
    """One line per locked compilation to ``$VOLUMEN_COMPILE_LOCK_LOG`` when set: worker, seconds waited for the
    other worker, seconds in ``compile`` (a cache load after a wait is quick), the test, the kernel."""
    path = os.environ.get("VOLUMEN_COMPILE_LOCK_LOG")
    if path:
        with open(path, "a") as f:
            test = os.environ.get("PYTEST_CURRENT_TEST", "-").split(" ")[0]
            f.write(f"{os.environ.get('PYTEST_XDIST_WORKER', '-')}\t{waited:.2f}\t{took:.2f}\t{test}\t{key}\n")


def _locked(original, lock_dir: Path, global_compiler_lock):
    def compile(self, sig):
        if type(getattr(self, "_cache", None)).__name__ == "NullCache":
            return original(self, sig)
        code = self.py_func.__code__
        key = f"{code.co_filename}:{self.py_func.__qualname__}:{sig}"
        with global_compiler_lock:  # first the process's own lock (as compile takes it): no thread holds
            t0 = time.monotonic()     # a file lock while another thread of its process compiles
            fd = _acquire(lock_dir / (hashlib.sha1(key.encode()).hexdigest() + ".lock"))
            t1 = time.monotonic()
            try:
                return original(self, sig)
            finally:
                if fd is not None:
                    fcntl.flock(fd, fcntl.LOCK_UN)
                    os.close(fd)
                _log(key, t1 - t0, time.monotonic() - t1)

    compile.__wrapped__ = original
    return compile


def install() -> bool:
    """Wrap ``numba.core.dispatcher.Dispatcher.compile`` once; whether it is wrapped (False where Numba's
    dispatcher has no ``compile(self, sig)``: the suite then runs as before)."""
    from numba.core import dispatcher
    from numba.core.compiler_lock import global_compiler_lock

    original = getattr(dispatcher.Dispatcher, "compile", None)
    if original is None or hasattr(original, "__wrapped__"):
        return original is not None
    dispatcher.Dispatcher.compile = _locked(original, _lock_dir(), global_compiler_lock)
    return True
