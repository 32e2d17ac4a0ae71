"""Pictures that display themselves in notebooks: PNG bytes and HTML for Image, Volume and Mesh.

``Image._repr_png_``, ``Volume._repr_png_`` / ``_repr_html_`` and ``Mesh._repr_png_`` call these
functions through ``volumen.core._repr`` (the root package registers :func:`make`; IPython asks for
them; nothing here imports IPython). Pillow is imported when a PNG is made.

:func:`mesh_picture` draws a triangle mesh without OpenGL: each triangle is sampled on a barycentric
grid no coarser than one pixel, the samples are projected orthographically, and a depth sort keeps
the nearest sample per pixel (a point-splat z-buffer in numpy). Two-sided Lambert shading along the
view axis. It is a thumbnail, not a renderer: ``volumen.render`` draws meshes with lights.
"""

from __future__ import annotations

import base64
import html
import io

import numpy as np

from ..core import montage

__all__ = ["make", "png_bytes", "image_png", "volume_png", "volume_html", "mesh_picture", "mesh_png",
           "MESH_VIEW", "MESH_COLOR"]

#: direction (RAS+) from the mesh toward the eye of :func:`mesh_picture`: anterior, a little left and above
MESH_VIEW = (-0.35, 1.0, 0.35)
#: linear RGB of a mesh thumbnail (the isosurface default)
MESH_COLOR = (0.9, 0.85, 0.75)
_MAX_SAMPLES = 4_000_000


def png_bytes(rgb: np.ndarray) -> bytes:
    """PNG file content of a uint8 ``(H, W)``, ``(H, W, 3)`` or ``(H, W, 4)`` array (row 0 at the top)."""
    from PIL import Image as PILImage

    buf = io.BytesIO()
    PILImage.fromarray(np.ascontiguousarray(rgb, dtype=np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def image_png(image) -> bytes:
    """PNG of a rendered :class:`~volumen.core.Image` over black, linear encoding (as ``Image.save``)."""
    return png_bytes(image.to_uint8())


def volume_png(volume) -> bytes:
    """PNG of the axial, coronal and sagittal planes through the centre (:func:`~volumen.core.montage`)."""
    return png_bytes(montage(volume))


def volume_html(volume) -> str:
    """A table of the volume's geometry (shape [z, y, x], spacing mm, orientation, values) beside its montage."""
    lo, hi = volume.value_range()
    rows = [("shape [z, y, x]", " x ".join(str(n) for n in volume.shape)),
            ("spacing (dz, dy, dx) mm", ", ".join(f"{s:.4g}" for s in volume.spacing)),
            ("orientation", volume.orientation + (" (oblique)" if volume.is_oblique else "")),
            ("extent mm", ", ".join(f"{e:.1f}" for e in volume.extent)),
            ("values", f"{lo:.6g} .. {hi:.6g} {volume.units or ''}".rstrip()),
            ("modality", volume.modality or "-")]
    cells = "".join(f"<tr><th style='text-align:left'>{html.escape(k)}</th><td>{html.escape(v)}</td></tr>"
                    for k, v in rows)
    src = base64.b64encode(volume_png(volume)).decode()
    return (f"<div style='display:flex;gap:12px;align-items:flex-end'><table>{cells}</table>"
            f"<img src='data:image/png;base64,{src}' alt='axial, coronal, sagittal'/></div>")


def _view_basis(view) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Right, up, forward unit vectors of an eye looking along ``-view`` with +z (superior) up."""
    f = -np.asarray(view, float) / np.linalg.norm(view)
    r = np.cross(f, (0.0, 0.0, 1.0))
    r /= np.linalg.norm(r)
    return r, np.cross(r, f), f


def mesh_picture(vertices, faces, size: int = 256, *, view=MESH_VIEW, color=MESH_COLOR,
                 ambient: float = 0.2) -> np.ndarray:
    """uint8 ``(size, size, 3)`` picture of a mesh seen orthographically along ``-view`` (RAS+ direction).

    ``vertices`` (N, 3) mm, ``faces`` (M, 3) int. The mesh's bounding sphere fills 90 % of the picture; a
    pixel showing a triangle with unit normal ``n`` gets ``color * (ambient + (1 - ambient) * |n . f|)``
    (``f`` the view axis), the background is black.
    """
    v = np.asarray(vertices, np.float64)
    f = np.asarray(faces, np.int64).reshape(-1, 3)
    out = np.zeros((size, size, 3), np.uint8)
    if len(f) == 0:
        return out
    r, u, fwd = _view_basis(view)
    centre = 0.5 * (v.min(0) + v.max(0))
    scale = 0.9 * size / max(2.0 * float(np.linalg.norm(v - centre, axis=1).max()), 1e-9)  # pixels per mm
    p = np.stack([(v - centre) @ r * scale + size / 2, size / 2 - (v - centre) @ u * scale, (v - centre) @ fwd], 1)
    tri = p[f]                                                        # (M, 3 corners, 3)
    edge = np.abs(tri[:, [1, 2, 0], :2] - tri[:, :, :2]).max()
    k = int(np.clip(np.ceil(edge) + 1, 2, max(2, np.sqrt(2 * _MAX_SAMPLES / len(f)) - 2)))
    a, b = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
    keep = a + b <= k
    w = np.stack([a[keep], b[keep], k - a[keep] - b[keep]], 1) / k    # (S, 3) barycentric weights
    pts = np.einsum("sc,mcd->msd", w, tri).reshape(-1, 3)
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    lit = np.abs(normal @ fwd) / np.maximum(np.linalg.norm(normal, axis=1), 1e-30)
    shade = np.repeat(ambient + (1 - ambient) * lit, len(w))
    ix, iy = np.floor(pts[:, 0]).astype(np.int64), np.floor(pts[:, 1]).astype(np.int64)
    inside = (ix >= 0) & (ix < size) & (iy >= 0) & (iy < size)
    pix, depth, shade = (iy * size + ix)[inside], pts[inside, 2], shade[inside]
    order = np.lexsort((depth, pix))                                  # nearest sample first within each pixel
    first = order[np.r_[True, pix[order][1:] != pix[order][:-1]]]
    rgb = np.rint(255 * np.clip(shade[first, None] * np.asarray(color, float), 0, 1)).astype(np.uint8)
    out.reshape(-1, 3)[pix[first]] = rgb
    return out


def mesh_png(mesh, size: int = 256) -> bytes:
    """PNG of :func:`mesh_picture` of a :class:`~volumen.surface.Mesh`."""
    return png_bytes(mesh_picture(mesh.vertices, mesh.faces, size))


_KINDS = {"image_png": image_png, "volume_png": volume_png, "volume_html": volume_html, "mesh_png": mesh_png}


def make(kind: str, obj):
    """The picture ``kind`` (``image_png``, ``volume_png``, ``volume_html``, ``mesh_png``) of ``obj``."""
    return _KINDS[kind](obj)
