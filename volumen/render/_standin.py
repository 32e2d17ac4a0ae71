"""A viewer's first picture in seconds: OpenGL stands in while a CPU ray-casting kernel compiles aside.

Each (mode, shading model) of the CPU ray caster has its own kernel, compiled by Numba on first use: 6-18 s on 2
cores (``volumen bench compile``), during which a viewer would show nothing. Compiling it in a thread of this
process while OpenGL draws does not work: a moderngl draw holds the GIL while Mesa renders, and a compile beside a
stream of OpenGL frames took 149 s instead of 14 s. So :func:`compiling` starts the kernel's compile in a child
process (:func:`~volumen.render.warm`, one worker, at normal priority), which puts it in Numba's disk cache; until
the child ends, the viewer draws its frames with the OpenGL ray caster (:func:`draw`: Mesa's llvmpipe where there
is no GPU; the same modes, shading models and transfer functions, within the tolerances of
``tests/render/raster``), at a reduced viewport, and shows them as not final. Then the CPU draws the picture,
loading the kernel from the cache (or compiling it itself, where the child failed).

A picture needs no stand-in when its kernel is ready (``_ready.is_ready``: drawn or warmed in this process, or
marked in the cache by an earlier one), when the CPU does not draw it (another device or technique; a chunked
volume, which the CPU draws out of core), when OpenGL's ray caster refuses the scene (path tracing, a composite
label map, more lights or clip planes than one pass takes: ``raster.check_scene``), when ``VOLUMEN_STANDIN`` is
``0``, or when no OpenGL context can be made here. A draw that fails all the same (a volume past the texture
limit) leaves the viewer to draw on the CPU, compiling beside the child. The desktop app's render worker and the
notebook's render loop ask; one-shot pictures (``volumen render``, ``render()``) never do: what they write comes
from the device they were given.
"""

from __future__ import annotations

import os
import threading

from ..core import is_chunked
from ._ready import is_ready, note_ready, when_ready
from ._reduced import render_reduced
from ._techniques import resolve_device
from ._warm import kernel_key, warm

__all__ = ["compiling", "draw", "usable", "drawn_at", "ENV", "FRACTION"]

#: environment variable: ``0`` turns stand-ins off (the first picture then waits for its kernel's compile)
ENV = "VOLUMEN_STANDIN"
#: side ratio of a stand-in's viewport, at most (a quarter of the pixels: llvmpipe draws a 512^2 frame of a
#: 200^3 volume in about 1.5 s on 2 cores, a 256^2 one in about 0.4 s)
FRACTION = 0.5

_lock = threading.Lock()
#: kernel_key -> Event set when its child has ended
_children: dict = {}
_gl: dict = {}


def _ended(key) -> None:
    """A kernel was noted ready (by its own child, or by another warm-up, such as the app's, that got there
    first): its stand-ins end."""
    with _lock:
        done = _children.get(key)
    if done is not None:
        done.set()


when_ready(_ended)


def usable() -> bool:
    """Whether this process can draw stand-ins: not turned off, and an OpenGL 3.3 context can be made (asked once)."""
    if os.environ.get(ENV, "1").strip() == "0":
        return False
    with _lock:
        if "ok" not in _gl:
            _gl["ok"] = _probe()
        return _gl["ok"]


def _probe() -> bool:
    try:
        from .raster import gl_renderer

        gl_renderer()
    except Exception:  # noqa: BLE001 - any failure means: no OpenGL here, the CPU draws the first picture
        return False
    return True


def _cpu_draws(scene, device, technique) -> bool:
    """Whether ``render`` draws this picture with a CPU ray-casting kernel (in memory)."""
    name = getattr(technique, "name", technique) or "raycast"
    return (name == "raycast" and resolve_device(device, "raycast") == "cpu" and scene.volume is not None
            and not is_chunked(scene.volume.data))


def _gl_draws(scene) -> bool:
    """Whether OpenGL's ray caster takes ``scene`` (``raster.check_scene``: its limits, checked before a draw)."""
    from ..errors import DeviceLimitError
    from .raster import check_scene

    try:
        check_scene(scene)
    except DeviceLimitError:
        return False
    return True


def compiling(scene, camera, device=None, technique=None) -> threading.Event | None:
    """None when the CPU should draw this picture now; else an Event that is set once the kernel's compile ends.

    The first ask for a kernel that is not ready starts its compile in a child process (see the module
    docstring); ``device`` and ``technique`` are ``render``'s. A stand-in is wanted while this returns an Event
    that is not set.
    """
    if not _cpu_draws(scene, device, technique):
        return None
    key = kernel_key(scene, camera)
    if is_ready(key) or not _gl_draws(scene) or not usable():
        return None
    with _lock:
        done = _children.get(key)
        if done is None:
            done = _children[key] = threading.Event()
            threading.Thread(target=_compile, args=(key, scene, camera, done), name="volumen-standin",
                             daemon=True).start()
    return None if done.is_set() else done


def _compile(key, scene, camera, done: threading.Event) -> None:
    try:
        warm([(scene, camera)], workers=1)
    except Exception:  # noqa: BLE001 - the CPU then compiles the kernel itself when it draws
        pass
    finally:
        note_ready(key)  # from the cache, or compiled on the CPU's first draw where the child failed
        done.set()


def drawn_at(fraction: float) -> float:
    """The viewport fraction a stand-in asked at ``fraction`` is drawn at (at most :data:`FRACTION`)."""
    return min(float(fraction), FRACTION)


def draw(scene, camera, size, fraction: float = 1.0):
    """The stand-in for the CPU's picture of ``scene``: the OpenGL ray caster at ``fraction`` of ``size`` (at most
    :data:`FRACTION`), upscaled; its ``stats["stand_in"]`` is True. Raises what OpenGL raises."""
    img = render_reduced(scene, camera, size, drawn_at(fraction), device="gl", technique="raycast")
    img.stats["stand_in"] = True
    return img
