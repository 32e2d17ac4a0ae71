"""The OpenGL context of the rasterized techniques: one headless (EGL) moderngl context per process,
current in one long-lived thread that every OpenGL call goes through (:func:`on_gl_thread`).

A headless context is current only in the thread that made it, and the texture,
table and program caches hold objects of that one context; so the public entry
points (:func:`gl_thread` decorates them) hop to the ``volumen-gl`` thread, from
whatever thread calls them (a GUI worker, pytest, a script).

moderngl is imported here, inside functions, so ``import volumen`` never loads
it. Without a GPU, Mesa's llvmpipe (software OpenGL 4.5) serves the same
context. Framebuffers are read back bottom-up by OpenGL; :func:`read_rgba` and
:func:`read_channel` flip them so row 0 is the TOP of the picture, as in
:class:`~volumen.core.Image`.
"""

from __future__ import annotations

import functools
import os
import threading

import numpy as np

__all__ = ["RasterUnavailable", "get_context", "context_info", "gl_renderer", "is_software_renderer",
           "SOFTWARE_RENDERERS", "Target", "PRECISIONS", "on_gl_thread", "gl_thread"]

#: blending precision -> moderngl texture dtype of the colour target
PRECISIONS = {"uint8": "f1", "float16": "f2", "float32": "f4"}

_lock = threading.Lock()
_state: dict = {}


_GL_THREAD = "volumen-gl"
_executor = None


def on_gl_thread(fn, *args, **kw):
    """Run ``fn(*args, **kw)`` on the process's one OpenGL thread and return its result (or raise its error)."""
    global _executor
    if threading.current_thread().name.startswith(_GL_THREAD):
        return fn(*args, **kw)
    with _lock:
        if _executor is None:
            from concurrent.futures import ThreadPoolExecutor

            _executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix=_GL_THREAD)
    return _executor.submit(fn, *args, **kw).result()


def gl_thread(fn):
    """Decorator: the function always runs on the OpenGL thread (see :func:`on_gl_thread`)."""

    @functools.wraps(fn)
    def wrapper(*args, **kw):
        return on_gl_thread(fn, *args, **kw)

    return wrapper


class RasterUnavailable(RuntimeError):
    """No OpenGL 3.3+ context can be created here (no EGL, no moderngl...); the message says why."""


@gl_thread
def get_context():
    """The process-wide headless moderngl context (OpenGL >= 3.3 core), created on first use.

    Tries EGL (headless; Mesa llvmpipe without a GPU), then the platform default.
    Set ``VOLUMEN_GL_BACKEND`` to force a moderngl backend name (``"egl"``...).

    Raises
    ------
    RasterUnavailable
        With every attempt's error when no context can be made.
    """
    with _lock:
        if "ctx" in _state:
            return _state["ctx"]
        if "error" in _state:
            raise RasterUnavailable(_state["error"])
        try:
            import moderngl
        except ImportError:  # pragma: no cover - depends on the install
            from ...errors import MissingExtraError

            _state["error"] = str(MissingExtraError("moderngl", "drawing on OpenGL"))
            raise RasterUnavailable(_state["error"]) from None
        forced = os.environ.get("VOLUMEN_GL_BACKEND")
        attempts = [forced] if forced else ["egl", None]
        errors = []
        for backend in attempts:
            try:
                kw = {"backend": backend} if backend else {}
                ctx = moderngl.create_standalone_context(require=330, **kw)
            except Exception as exc:  # noqa: BLE001 - every failure is reported below
                errors.append(f"{backend or 'default'}: {type(exc).__name__}: {exc}")
                continue
            _state["ctx"] = ctx
            return ctx
        _state["error"] = "no OpenGL 3.3 context could be created (" + "; ".join(errors) + ")"
        raise RasterUnavailable(_state["error"])


@gl_thread
def context_info() -> dict:
    """Renderer, version and vendor strings of the context (creates it)."""
    info = get_context().info
    return {k: info.get(k) for k in ("GL_RENDERER", "GL_VERSION", "GL_VENDOR")}


#: renderer names of OpenGL implementations that rasterize on the CPU (Mesa's llvmpipe, softpipe and swrast,
#: Google's SwiftShader, Windows' basic render driver): slower than the CPU ray caster
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "swiftshader", "software rasterizer", "basic render driver")


def is_software_renderer(renderer: str) -> bool:
    """Whether the ``GL_RENDERER`` string names a software rasterizer (:data:`SOFTWARE_RENDERERS`)."""
    name = (renderer or "").lower()
    return any(s in name for s in SOFTWARE_RENDERERS)


def gl_renderer() -> tuple[str, bool]:
    """``(GL_RENDERER, hardware)`` of this process's context; raises :class:`RasterUnavailable` without one."""
    name = str(context_info().get("GL_RENDERER") or "unknown")
    return name, not is_software_renderer(name)


class Target:
    """An offscreen framebuffer: colour attachments of given precision plus an optional depth buffer.

    Parameters
    ----------
    ctx : moderngl.Context
    size : (width, height), pixels
    colors : sequence of (components, dtype)
        One colour attachment each; dtype a moderngl texture dtype
        (``"f1"`` 8-bit normalized, ``"f2"`` half float, ``"f4"`` float).
    depth : bool
        Attach a depth buffer (for meshes).
    """

    def __init__(self, ctx, size, colors, depth: bool = False):
        self.ctx = ctx
        self.size = (int(size[0]), int(size[1]))
        self.textures = [ctx.texture(self.size, c, dtype=d) for c, d in colors]
        self.depth = ctx.depth_renderbuffer(self.size) if depth else None
        self.fbo = ctx.framebuffer(color_attachments=self.textures, depth_attachment=self.depth)

    def use(self) -> None:
        self.fbo.use()
        self.ctx.viewport = (0, 0, *self.size)

    def read(self, attachment: int = 0, components: int = 4) -> np.ndarray:
        """Attachment as float32 ``(H, W, components)``, row 0 at the TOP (flipped from OpenGL)."""
        w, h = self.size
        raw = self.fbo.read(components=components, attachment=attachment, dtype="f4")
        return np.frombuffer(raw, np.float32).reshape(h, w, components)[::-1].copy()

    def release(self) -> None:
        self.fbo.release()
        for t in self.textures:
            t.release()
        if self.depth is not None:
            self.depth.release()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()
