"""Public entry points of the renderers: ``render`` and ``render_volume``."""

from __future__ import annotations

import warnings
import weakref

from ..core import (
    Camera,
    Image,
    Isosurface,
    Sampling,
    Scene,
    Shading,
    TransferFunction,
    default_camera,
    default_iso,
    default_preset,
    fitted_preset,
    is_chunked,
    is_color_slab,
)
from ..core._camera import Projection, View
from ..core._scene import Mode, ShadingMode
from ..core._transfer import Preset
from ._ready import note_ready
from ._slab import kept_for, slabbed
from ._techniques import Technique, legacy_backend, resolve_device
from ._warm import kernel_key

__all__ = ["render", "render_volume", "clear_cache", "default_mode", "default_transfer", "default_shading",
           "default_look"]


def _choose(device, technique, options, backend) -> tuple[str, Technique]:
    """(resolved device, Technique) from ``render``'s arguments."""
    if backend is not None:
        warnings.warn("render(backend=...) is deprecated: use device= and technique= (volumen.render.DEVICES, "
                      "TECHNIQUES)", DeprecationWarning, stacklevel=3)
        device, technique = legacy_backend(backend)
    if isinstance(technique, Technique):
        if options:
            technique = Technique(technique.name, technique.options, **options)
    elif isinstance(technique, str):
        technique = Technique(technique, **options)
    else:
        raise ValueError(f"technique must be a name or a Technique, got {type(technique).__name__}")
    return resolve_device(device, technique.name), technique


def render(scene: Scene, camera: Camera, size: tuple[int, int] = (512, 512), *, device: str | None = None,
           technique: str | Technique = "raycast", backend: str | None = None, memory: int | str = "4GB",
           brick: int | None = None, **options) -> Image:
    """Render a scene.

    Parameters
    ----------
    scene : Scene
        Must hold its ``volume`` (a :class:`~volumen.core.Volume`). A colour
        volume (``volume.is_color``) is classified by its luminance (opacity,
        normals, shadows; MIP / MinIP / average project the luminance) and the
        ray caster's composite samples emit the voxels' own RGB instead of the
        table's colour; slicing and mesh draw the luminance. A chunked volume
        (``volumen.load`` of an OME-Zarr image: read lazily) is ray cast out of
        core on the CPU (:func:`volumen.render.bricked.render_bricked`): brick by
        brick through a chunk cache of at most ``memory`` bytes, equal to the
        whole volume drawn at once; modes composite, mip and minip, shading none,
        headlight or phong.
    camera : Camera
    size : (width, height), pixels
    device : one of :data:`~volumen.render.DEVICES`, or None
        ``"cpu"`` (Numba), ``"cuda"`` (the same kernels on an NVIDIA GPU;
        raises :class:`~volumen.render.cuda.CudaUnavailableError` where there
        is none), ``"gl"`` (OpenGL), ``"auto"`` (the technique's best usable
        device: ``"cuda"`` for ray casting when a device is usable); None: the
        technique's default (``"cpu"`` for ray casting, ``"gl"`` for slicing and mesh).
    technique : one of :data:`~volumen.render.TECHNIQUES`, or a :class:`~volumen.render.Technique`
        ``"raycast"``, ``"slicing"`` or ``"mesh"``.
    **options
        The technique's options (:func:`~volumen.render.option_choices`), e.g.
        ``precision="uint8"``, ``planes="near-quarter"`` for slicing,
        ``shading="gouraud"`` for mesh.
    backend : str, deprecated
        A backend name of volumen 0.1 (``"cpu"``, ``"slicing-uint8"``...);
        warns and stands for its device and technique.
    memory : bytes or str (``"4GB"``)
        A chunked volume: bound of its chunk cache.
    brick : int, optional
        A chunked volume: cells per brick side (default: the whole number of
        chunks closest to 128 voxels).

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
        volume). ``stats``: ``timings`` (seconds: normalize/normals/blocks/cells when
        built, tables, kernel, total), ``samples`` taken, ``rays``, ``rays_hit`` (rays that took a sample: a ray
        whose samples all fell in transparent cells, ``raycast._cells``, takes none).

        Shading ``shadows`` / ``scattering`` reports ``light_volumes`` seconds
        in the timings when illumination volumes were (re)built, and
        ``light_volumes_built``; shading ``pathtrace`` (composite mode) runs
        ``scene.shading.pt_samples`` samples per pixel of :class:`PathTracer`
        and reports ``spp``; its depth is the mean distance of the first
        scattering event. ``stats["renderer"]``: the ``device`` and ``technique`` that drew it.
        ``display``: the scene's :class:`~volumen.core.Display` resolved for its shading (``auto``: the filmic
        curve for the lit models), which ``Image.to_uint8`` / ``Image.save`` apply. A chunked volume's
        ``stats`` also hold ``bricks``, ``bricks_drawn``, ``chunk_reads`` (from the store) and
        ``cache_peak_bytes``.
    """
    chunked = isinstance(scene, Scene) and scene.volume is not None and is_chunked(scene.volume.data)
    if chunked and device in (None, "auto") and getattr(technique, "name", technique) == "raycast":
        device = "cpu"  # the bricks are ray cast on the CPU
    device, technique = _choose(device, technique, options, backend)
    w, h = _checked(scene, camera, size)
    if chunked:
        image = _out_of_core(slabbed(scene), camera, (w, h), device, technique, memory, brick)
    else:
        image = technique.spec.draw(_drawn(scene, technique), camera, (w, h), device, technique.options)
        if device == "cpu" and technique.name == "raycast":
            note_ready(kernel_key(scene, camera))  # its kernel is compiled now (volumen.render._standin asks)
    image.stats["renderer"] = {"device": device, "technique": technique.name}
    image.display = scene.display.resolved(scene.shading.mode, scene.mode)
    return image


def _checked(scene, camera, size) -> tuple[int, int]:
    """``(width, height)`` of a valid call, else a one-line ``ValueError``."""
    if not isinstance(scene, Scene):
        raise ValueError(f"scene must be a Scene, got {type(scene).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be a Camera, got {type(camera).__name__}")
    if scene.volume is None:
        raise ValueError("scene.volume is None: attach the Volume (Scene(volume=...) or "
                         "Scene.from_dict(d, volume=...))")
    try:
        w, h = (int(s) for s in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be (width, height) in pixels, got {size!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ValueError(f"size must be (width, height) with 1..16384 pixels each, got {size!r}")
    return w, h


def _out_of_core(scene, camera, size, device, technique, memory, brick) -> Image:
    """A chunked volume ray cast brick by brick on the CPU (:mod:`volumen.render.bricked`)."""
    if technique.name != "raycast" or device != "cpu":
        raise ValueError(f"a chunked volume (OME-Zarr, read lazily) is ray cast out of core on the cpu, not drawn "
                         f"by {technique.name} on {device}: use technique='raycast', device='cpu', or read it into "
                         "memory first (volume.with_data(volume.data[...]))")
    from .bricked import render_bricked  # Numba loads here, not at import

    return render_bricked(scene, camera, size, memory=memory, brick=brick)


_LUMINANCE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _luminance_volume(volume):
    """The scalar volume of a colour volume's luminance (kept while the colour volume and its data live)."""
    return kept_for(_LUMINANCE, volume, lambda v: v.with_data(v.luminance()))


def _drawn(scene, technique):
    """The scene as ``technique`` draws it: a single slice as its slab (:func:`._slab.slabbed`), a colour volume's
    luminance for slicing and mesh."""
    scene = slabbed(scene)
    if scene.volume.is_color and technique.name != "raycast":  # slicing and mesh draw the luminance
        scene = scene.with_(volume=_luminance_volume(scene.volume))
    return scene


def default_mode(volume) -> Mode:
    """The mode a volume is drawn in when neither a mode nor a transfer function nor labels are named:
    ``"composite"``, or ``"mip"`` for a scalar slab of one or two samples (a single slice, two frames:
    :attr:`Volume.thin_axis`), whose few millimetres of tissue composite to a faint, dark picture where its MIP is
    the image itself. A thicker slab (a stack of slices) is composited, and so is a colour slab: its MIP would
    project the luminance, grey."""
    thin = volume.thin_axis
    return "mip" if thin is not None and volume.shape[thin] <= 2 and not volume.is_color else "composite"


def default_shading(volume, mode: Mode | None = None) -> ShadingMode:
    """The shading a volume is drawn with in ``mode`` when none is named: ``"headlight"``, or ``"none"`` for a
    colour slab (:func:`volumen.core.is_color_slab`: an ultrasound frame, a photograph) composited, drawn as the
    image it is. Seen face-on, such a frame's gradients lie in its plane, at right angles to the view, so the
    headlight lit it by its ambient term alone: pydicom's frames at a fifth to a half of their brightness. Its
    isosurface keeps the headlight (unshaded, it is a flat silhouette)."""
    return "none" if is_color_slab(volume) and mode != "isosurface" else "headlight"


def default_transfer(volume, mode: Mode) -> TransferFunction:
    """The transfer function ``render_volume`` uses when none is named (:func:`volumen.core.default_preset`): gray
    ramp over the data range for projections (opaque for a colour slab), ``ct-skin-bone`` for CT (on its stored
    values), ``mr-default`` over the display range otherwise (``core.display_range``: less a few far outliers)."""
    return default_preset(volume, mode)


def default_look(volume, mode: Mode | None = None, *,
                 transfer_named: bool = False) -> tuple[Mode, TransferFunction, ShadingMode]:
    """``(mode, transfer function, shading)``: what a volume is drawn with where nothing else is named, the one
    answer of ``render_volume``, the command line, the app and ``volumen.show``. The mode is ``mode`` if named,
    composite where a transfer function is named (or labels colour it), else :func:`default_mode`; the transfer
    function and the shading are those for it (:func:`default_transfer`, :func:`default_shading`)."""
    mode = mode or ("composite" if transfer_named else default_mode(volume))
    return mode, default_transfer(volume, mode), default_shading(volume, mode)


def render_volume(volume, *, preset: Preset | TransferFunction | None = None, view: View | None = None,
                  mode: Mode | None = None, projection: Projection = "perspective",
                  size: tuple[int, int] = (512, 512), shading: ShadingMode | None = None, azimuth: float = 0.0,
                  elevation: float = 0.0, zoom: float = 1.0, samples_per_voxel: float = 1.0,
                  iso_value: float | None = None, device: str | None = None,
                  technique: str | Technique = "raycast", **options) -> Image:
    """Render a volume in one call.

    Parameters
    ----------
    volume : Volume
    preset : str, TransferFunction or None
        A preset name (``volumen.core.PRESETS``) or a transfer function;
        None picks :func:`default_transfer`.
    view, azimuth, elevation, zoom, projection :
        As in :meth:`volumen.core.Camera.orbit`; the camera is fitted to the subject (``core.default_camera``).
    mode : {"composite", "mip", "minip", "average", "isosurface"} or None
        None: composite, or with no ``preset`` :func:`default_mode` (MIP for a scalar slab).
    size : (width, height), pixels
    shading : {"none", "headlight", "phong", "shadows", "scattering", "pathtrace"} or None
        ("phong" and the lit models without lights show ambient light only.) None: :func:`default_shading`
        (the headlight; none for a colour slab composited).
    samples_per_voxel : float
    iso_value : float or None
        Isosurface threshold in data units; None: 300 HU for CT, the middle
        of the value range otherwise.
    device, technique, **options :
        As in :func:`render`.
    """
    mode, tf, shaded = default_look(volume, mode, transfer_named=preset is not None)
    if isinstance(preset, TransferFunction):
        tf = preset
    elif preset is not None:
        tf = fitted_preset(preset, volume)
    if iso_value is None:
        iso_value = default_iso(volume)
    scene = Scene(volume=volume, transfer=tf, mode=mode, shading=Shading(mode=shading or shaded),
                  sampling=Sampling(samples_per_voxel=samples_per_voxel), isosurface=Isosurface(value=iso_value))
    camera = default_camera(volume, azimuth=azimuth, elevation=elevation, zoom=zoom, view=view, projection=projection)
    return render(scene, camera, size, device=device, technique=technique, **options)


def clear_cache(volume=None) -> None:
    """Forget cached per-volume precomputations (after changing ``volume.data`` in place)."""
    from .raycast import clear_cache as _clear

    _clear(volume)
