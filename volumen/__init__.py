"""volumen: seeing inside medical volumes (CT, MRI).

``import volumen`` is cheap: the readers, renderers and Qt are imported only
when first used. This root module also hands ``volumen.core`` its notebook picture maker
(:func:`_notebook_picture`), so the plain data shows itself without importing upward.
"""

from __future__ import annotations

from .core import Volume
from .core._repr import set_picture_maker
from .errors import VolumenError, VolumeReadError, VolumeWriteError

__all__ = ["Volume", "VolumeReadError", "VolumeWriteError", "VolumenError", "load", "load_labels", "load_measurements",
           "save", "show", "__version__"]
__version__ = "0.1.0"


def load(path, **options) -> Volume:
    """Read a volume file or DICOM folder (see :func:`volumen.io.load`), or a series of an archive,
    ``dicomweb://SERVER/STUDY/SERIES``, retrieved into the cache first (see :func:`volumen.pacs.load`)."""
    if isinstance(path, str) and path.startswith(("dicomweb://", "dimse://")):
        from .pacs import load as _load_archived

        return _load_archived(path, **options)
    from .io import load as _load

    return _load(path, **options)


def load_measurements(path, volume=None):
    """Read measurements back: a DICOM SR volumen (or another TID 1500 writer) wrote, or a session / JSON file; with
    ``volume``, check they belong to its scan (see :func:`volumen.measure.load_measurements`)."""
    from .measure import load_measurements as _load_measurements

    return _load_measurements(path, volume=volume)


def __getattr__(name: str):
    """``volumen.measure`` without importing it first (a notebook's ``volumen.measure.distance(p, q)``)."""
    if name == "measure":
        import importlib

        return importlib.import_module(".measure", __name__)
    raise AttributeError(f"module 'volumen' has no attribute {name!r}")


def load_labels(path, **options):
    """Read a segmentation (label map + names, .seg.nrrd, DICOM SEG, folder of masks); see
    :func:`volumen.io.load_labels`."""
    from .io import load_labels as _load_labels

    return _load_labels(path, **options)


def save(volume: Volume, path, **options) -> None:
    """Write a volume; see :func:`volumen.io.save`."""
    from .io import save as _save

    _save(volume, path, **options)


def show(volume_or_scene, camera=None, **options):
    """An interactive 3-D view with controls and slice views in Jupyter; see :func:`volumen.notebook.show`."""
    from .notebook import show as _show

    return _show(volume_or_scene, camera, **options)


def _notebook_picture(kind: str, obj):
    """The notebook picture of an Image, Volume or Mesh (``volumen.core._repr``), made on the notebook floor."""
    from .notebook import pictures

    return pictures.make(kind, obj)


set_picture_maker(_notebook_picture)
