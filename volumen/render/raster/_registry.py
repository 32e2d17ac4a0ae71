"""The registry of rasterized techniques: one named entry per technique and variant.

Each entry is a callable ``(scene, camera, size) -> Image`` like every backend of
``volumen.render.render``; :func:`register_backends` adds them all to a
backend table (``volumen.render.BACKENDS``) under their names.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ._mesh import MeshOptions, render_isosurface_mesh
from ._slicing import SlicingOptions, render_slicing

__all__ = ["Technique", "TECHNIQUES", "register_backends"]


@dataclass(frozen=True)
class Technique:
    """A named rasterized technique with fixed options; call it as a backend.

    Attributes
    ----------
    name : str
        Backend name (``"slicing"``, ``"slicing-uint8"``, ``"mesh"``...).
    kind : {"slicing", "mesh"}
    options : SlicingOptions or MeshOptions
    description : str
    """

    name: str
    kind: str
    options: SlicingOptions | MeshOptions
    description: str

    def __call__(self, scene, camera, size):
        if self.kind == "slicing":
            return render_slicing(scene, camera, size, self.options)
        return render_isosurface_mesh(scene, camera, size, self.options)


def _entries():
    S, M = SlicingOptions, MeshOptions
    rows = [
        ("slicing", "slicing", S(), "texture slicing, back to front, float32 target, post-classification"),
        ("slicing-front-to-back", "slicing", S(order="front-to-back"), "texture slicing blended front to back"),
        ("slicing-pre", "slicing", S(classification="pre"), "texture slicing, pre-classification"),
        ("slicing-uint8", "slicing", S(precision="uint8"), "texture slicing into an 8-bit target (banding)"),
        ("slicing-float16", "slicing", S(precision="float16"), "texture slicing into a half-float target"),
        ("slicing-near-quarter", "slicing", S(planes="near-quarter"),
         "adaptive: 2/3 of the planes in the first quarter of the near-far distance"),
        ("slicing-diagonal-quarter", "slicing", S(planes="diagonal-quarter"),
         "adaptive: 2/3 of the planes within a quarter of the volume diagonal"),
        ("slicing-two-per-voxel", "slicing", S(planes="two-per-voxel"), "two planes per voxel everywhere"),
        ("slicing-two-then-one", "slicing", S(planes="two-then-one"),
         "two planes per voxel up to a quarter of the diagonal, one beyond"),
        ("mesh", "mesh", M(), "marching-cubes isosurface drawn with per-pixel Phong shading"),
        ("mesh-gouraud", "mesh", M(shading="gouraud"), "marching-cubes isosurface, Gouraud shading"),
    ]
    return {name: Technique(name, kind, opt, desc) for name, kind, opt, desc in rows}


#: technique name -> Technique (a backend callable)
TECHNIQUES: dict[str, Technique] = _entries()


def register_backends(backends: dict[str, Callable] | None = None) -> dict[str, Callable]:
    """Add every technique of :data:`TECHNIQUES` to ``backends`` (default: ``volumen.render.BACKENDS``).

    Nothing OpenGL is loaded here; a context is made on the first render.
    Returns the table.
    """
    if backends is None:
        from .._api import BACKENDS as backends
    for name, tech in TECHNIQUES.items():
        backends.setdefault(name, tech)
    return backends
