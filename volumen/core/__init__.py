"""Plain data of volumen: volumes, slices, cameras, transfer functions, lights, scenes, images. numpy only.

:mod:`volumen.core.gestures` turns mouse drags into cameras and lights (the app and the notebook share it).
Image, Volume and Mesh show themselves in notebooks through pictures made above core
(:mod:`volumen.notebook.pictures`, registered by the root package: :mod:`._repr`)."""

from . import gestures
from ._camera import FITS, SUBJECT_FILL, VIEWS, Camera, default_camera, default_view
from ._ct import is_ct
from ._display import default_iso, display_range, drawable_range, table_range
from ._environment_light import ENVIRONMENTS, Environment, studio_lights, studio_sky
from ._image import Image
from ._label_slices import label_slice, outline_overlay
from ._labels import LabelLayer, LabelMap, default_color
from ._lighting import FACING
from ._projection import projection_window
from ._scene import (
    ADAPTIVE_SHADINGS,
    INTERPOLATIONS,
    MODES,
    SHADINGS,
    Clipping,
    ClipPlane,
    Isosurface,
    Light,
    Sampling,
    Scene,
    Shading,
    adaptive_on,
)
from ._slices import (
    PLANES,
    WINDOW_PRESETS,
    Window,
    canonical,
    default_window,
    montage,
    named_window,
    slice_at,
    slice_image,
    window_to_uint8,
)
from ._subject import subject_corners, subject_level
from ._tonemap import TONEMAPS, Display
from ._transfer import PRESETS, TransferFunction, default_preset, fitted_preset, hu_offset, is_color_slab
from ._units import mm_text, range_text, value_text, values_of
from ._volume import Volume, axis_codes, is_chunked

__all__ = [
    "gestures",
    "value_text",
    "range_text",
    "mm_text",
    "values_of",
    "ADAPTIVE_SHADINGS",
    "adaptive_on",
    "Volume",
    "LabelMap",
    "LabelLayer",
    "default_color",
    "label_slice",
    "outline_overlay",
    "axis_codes",
    "is_chunked",
    "Camera",
    "VIEWS",
    "default_view",
    "default_camera",
    "FITS",
    "SUBJECT_FILL",
    "projection_window",
    "subject_corners",
    "subject_level",
    "TransferFunction",
    "PRESETS",
    "default_preset",
    "is_color_slab",
    "hu_offset",
    "default_iso",
    "display_range",
    "table_range",
    "drawable_range",
    "fitted_preset",
    "is_ct",
    "FACING",
    "Light",
    "Shading",
    "Sampling",
    "ClipPlane",
    "Clipping",
    "Isosurface",
    "Scene",
    "MODES",
    "INTERPOLATIONS",
    "SHADINGS",
    "Image",
    "Display",
    "TONEMAPS",
    "Environment",
    "ENVIRONMENTS",
    "studio_lights",
    "studio_sky",
    "PLANES",
    "WINDOW_PRESETS",
    "Window",
    "canonical",
    "default_window",
    "named_window",
    "montage",
    "slice_at",
    "slice_image",
    "window_to_uint8",
]
