"""Is a CUDA device usable? One place for the question and for the error when it is not."""

from __future__ import annotations

import importlib.util

from ...errors import VolumenError

__all__ = ["CudaUnavailableError", "cuda_status", "cuda_available", "require_cuda", "simulator"]


class CudaUnavailableError(VolumenError, RuntimeError):
    """The ``cuda`` backend was asked for where no CUDA device can be used."""


def simulator() -> bool:
    """True when numba runs CUDA kernels in its simulator (``NUMBA_ENABLE_CUDASIM=1`` before numba loaded)."""
    from numba import config

    return bool(config.ENABLE_CUDASIM)


def cuda_status() -> tuple[bool, str]:
    """``(usable, description)``: whether CUDA kernels can run here, and the device or the reason why not.

    The simulator counts as usable (it runs every kernel, slowly, in Python
    threads); :func:`cuda_available` tells it apart.
    """
    try:
        from numba import cuda
    except Exception as exc:  # noqa: BLE001 - numba without its CUDA target, or a broken install
        return False, f"numba's CUDA target cannot be imported ({type(exc).__name__}: {exc})"
    if simulator():
        return True, "numba CUDA simulator (NUMBA_ENABLE_CUDASIM=1)"
    if importlib.util.find_spec("numba_cuda") is None:  # numba's built-in target cannot compile the kernels
        return False, ("no CUDA device is available to volumen: numba-cuda is not installed "
                       "(pip install 'volumen[cuda]')")
    try:
        if not cuda.is_available():
            return False, "no CUDA device is available (no NVIDIA GPU or driver found by numba.cuda)"
        dev = cuda.get_current_device()
        name = dev.name.decode() if isinstance(dev.name, bytes) else str(dev.name)
        return True, f"{name} (compute capability {dev.compute_capability[0]}.{dev.compute_capability[1]})"
    except Exception as exc:  # noqa: BLE001 - driver present but unusable
        return False, f"no CUDA device is available ({type(exc).__name__}: {exc})"


def cuda_available(simulator_ok: bool = False) -> bool:
    """True when a CUDA device is usable (the simulator only with ``simulator_ok``)."""
    ok, _ = cuda_status()
    return ok and (simulator_ok or not simulator())


def require_cuda() -> str:
    """The device's description; raises :class:`CudaUnavailableError` (saying why) when there is none."""
    ok, what = cuda_status()
    if not ok:
        raise CudaUnavailableError(f"backend 'cuda': {what}; use backend 'cpu' (or 'auto', which picks the CPU "
                                   "here)")
    return what
