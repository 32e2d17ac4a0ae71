"""Rasterized techniques on OpenGL (moderngl, headless EGL; Mesa llvmpipe without a GPU).

* texture slicing (:func:`render_slicing`, :class:`SlicingOptions`): view-aligned
  planes through a 3-D texture, blended back to front or front to back into an
  8-bit, half-float or float target, pre- or post-classification, uniform or
  adaptive plane distributions (:data:`ADAPTIVE`), Phong from gradients;
* meshes (:func:`render_mesh`, :func:`render_isosurface_mesh`,
  :class:`MeshOptions`): Phong or Gouraud, any lights, ``Image.depth`` written;
* ray casting (:func:`render_raycast_gl`): the CPU ray caster's packed frame marched
  by a fragment shader, every mode and shading model but path tracing.

Slicing and mesh are techniques of ``volumen.render.render`` on device ``gl``
(registered in ``volumen.render.TECHNIQUES``, their options the dataclasses
here). Shaders are the ``.glsl`` files in ``shaders/``. Nothing here imports
OpenGL until a picture is drawn.
"""

from ._context import (
    PRECISIONS,
    RasterUnavailable,
    context_info,
    get_context,
    gl_renderer,
    is_software_renderer,
    on_gl_thread,
)
from ._mesh import MeshOptions, clear_mesh_cache, isosurface_mesh, render_isosurface_mesh, render_mesh
from ._planes import ADAPTIVE, slab_boundaries, slice_polygons
from ._raycast import MAX_LIGHTS, MAX_PLANES, check_scene, render_raycast_gl
from ._slicing import SlicingOptions, render_slicing
from ._textures import clear_cache

__all__ = [
    "gl_renderer",
    "is_software_renderer",
    "render_raycast_gl",
    "check_scene",
    "MAX_LIGHTS",
    "MAX_PLANES",
    "on_gl_thread",
    "render_slicing",
    "SlicingOptions",
    "ADAPTIVE",
    "PRECISIONS",
    "slab_boundaries",
    "slice_polygons",
    "render_mesh",
    "render_isosurface_mesh",
    "isosurface_mesh",
    "MeshOptions",
    "get_context",
    "context_info",
    "RasterUnavailable",
    "clear_cache",
    "clear_mesh_cache",
]
