"""Public entry points of the renderers: ``render`` and ``render_volume``."""

from __future__ import annotations

from collections.abc import Callable

from ..core import Camera, Image, Isosurface, Sampling, Scene, Shading, TransferFunction
from ..core._camera import Projection, View
from ..core._scene import Mode, ShadingMode
from ..core._transfer import Preset

__all__ = ["render", "render_volume", "clear_cache", "BACKENDS", "auto_backend"]


def _cpu(scene: Scene, camera: Camera, size: tuple[int, int]) -> Image:
    from .raycast import render_cpu  # Numba loads here, not at import

    return render_cpu(scene, camera, size)


def _cuda(scene: Scene, camera: Camera, size: tuple[int, int]) -> Image:
    from .cuda import render_cuda  # numba.cuda loads here, not at import

    return render_cuda(scene, camera, size)


def auto_backend() -> str:
    """The backend ``"auto"`` stands for: ``"cuda"`` when a CUDA device is usable (never the simulator),
    else ``"cpu"``."""
    from .cuda import cuda_available

    return "cuda" if cuda_available() else "cpu"


def _auto(scene: Scene, camera: Camera, size: tuple[int, int]) -> Image:
    return BACKENDS[auto_backend()](scene, camera, size)


#: backend name -> function(scene, camera, size) -> Image
BACKENDS: dict[str, Callable[[Scene, Camera, tuple[int, int]], Image]] = {"cpu": _cpu, "cuda": _cuda, "auto": _auto}

# the OpenGL techniques (texture slicing variants, meshes); moderngl loads only when one draws
from .raster import register_backends  # noqa: E402

register_backends(BACKENDS)


def render(scene: Scene, camera: Camera, size: tuple[int, int] = (512, 512), *, backend: str = "cpu") -> Image:
    """Render a scene.

    Parameters
    ----------
    scene : Scene
        Must hold its ``volume`` (a :class:`~volumen.core.Volume`).
    camera : Camera
    size : (width, height), pixels
    backend : str
        A key of :data:`BACKENDS`: ``"cpu"`` (Numba ray casting), ``"cuda"``
        (the same kernels on an NVIDIA GPU; raises
        :class:`~volumen.render.cuda.CudaUnavailableError` where there is
        none), ``"auto"`` (``"cuda"`` when a device is usable, else ``"cpu"``).

    Returns
    -------
    Image
        ``rgba`` (H, W, 4) float32 premultiplied linear in [0, 1], row 0 at
        the top; ``depth`` (H, W) float32 mm along each view ray from the eye
        (orthographic: from the image plane), inf where nothing was hit --
        composite: where the accumulated opacity first reaches 0.5; mip/minip:
        where the extreme value was first met; average: the ray's entry into
        the drawn region; isosurface: the surface. ``value`` (H, W) for
        mip/minip/average: the projected value in data units (NaN off the
        volume). ``stats``: ``timings`` (seconds: normalize/normals/blocks when
        built, tables, kernel, total), ``samples`` taken, ``rays``, ``rays_hit``.

        Shading ``shadows`` / ``scattering`` reports ``light_volumes`` seconds
        in the timings when illumination volumes were (re)built, and
        ``light_volumes_built``; shading ``pathtrace`` (composite mode) runs
        ``scene.shading.pt_samples`` samples per pixel of :class:`PathTracer`
        and reports ``spp``; its depth is the mean distance of the first
        scattering event.
    """
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; valid: {', '.join(BACKENDS)}")
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be a Scene, got {type(scene).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
    if scene.volume is None:
        raise ValueError("scene.volume is None: attach the Volume (Scene(volume=...) or Scene.from_dict(d, volume=...))")
    try:
        w, h = (int(s) for s in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be (width, height) in pixels, got {size!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ValueError(f"size must be (width, height) with 1..16384 pixels each, got {size!r}")
    return BACKENDS[backend](scene, camera, (w, h))


def default_transfer(volume, mode: Mode) -> TransferFunction:
    """The transfer function ``render_volume`` uses when none is named: gray ramp over the data range
    for projections, ``ct-bone`` for CT, ``mr-default`` otherwise."""
    if mode in ("mip", "minip", "average"):
        return TransferFunction.preset("mip-gray", value_range=volume.value_range())
    if volume.modality == "CT" or volume.units == "HU":
        return TransferFunction.preset("ct-bone")
    return TransferFunction.preset("mr-default", value_range=volume.value_range())


def render_volume(volume, *, preset: Preset | TransferFunction | None = None, view: View = "anterior",
                  mode: Mode = "composite", projection: Projection = "perspective",
                  size: tuple[int, int] = (512, 512), shading: ShadingMode = "headlight", azimuth: float = 0.0,
                  elevation: float = 0.0, zoom: float = 1.0, samples_per_voxel: float = 1.0,
                  iso_value: float | None = None, backend: str = "cpu") -> Image:
    """Render a volume in one call.

    Parameters
    ----------
    volume : Volume
    preset : str, TransferFunction or None
        A preset name (``volumen.core.PRESETS``) or a transfer function;
        None picks :func:`default_transfer`.
    view, azimuth, elevation, zoom, projection :
        As in :meth:`volumen.core.Camera.orbit`.
    mode : {"composite", "mip", "minip", "average", "isosurface"}
    size : (width, height), pixels
    shading : {"none", "headlight", "phong", "shadows", "scattering", "pathtrace"}
        ("phong" and the lit models without lights show ambient light only.)
    samples_per_voxel : float
    iso_value : float or None
        Isosurface threshold in data units; None: 300 HU for CT, the middle
        of the value range otherwise.
    """
    if isinstance(preset, TransferFunction):
        tf = preset
    elif preset is None:
        tf = default_transfer(volume, mode)
    else:
        tf = TransferFunction.preset(preset, value_range=volume.value_range())
    if iso_value is None:
        lo, hi = volume.value_range()
        iso_value = 300.0 if (volume.modality == "CT" or volume.units == "HU") else 0.5 * (lo + hi)
    scene = Scene(volume=volume, transfer=tf, mode=mode, shading=Shading(mode=shading),
                  sampling=Sampling(samples_per_voxel=samples_per_voxel), isosurface=Isosurface(value=iso_value))
    camera = Camera.orbit(volume, azimuth=azimuth, elevation=elevation, zoom=zoom, view=view, projection=projection)
    return render(scene, camera, size, backend=backend)


def clear_cache(volume=None) -> None:
    """Forget cached per-volume precomputations (after changing ``volume.data`` in place)."""
    from .raycast import clear_cache as _clear

    _clear(volume)
