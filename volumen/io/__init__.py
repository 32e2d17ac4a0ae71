"""Reading and writing volume files (one module per family of formats).

Libraries used: pydicom (DICOM), nibabel (NIfTI), pynrrd (NRRD), SimpleITK
(MetaImage), numpy (.npy/.npz, raw); VTK legacy structured points are parsed here.
"""

from ._api import READ_FORMATS, WRITE_FORMATS, detect_format, load, save
from ._dicom_listing import SeriesSummary, list_series

__all__ = ["load", "save", "detect_format", "list_series", "SeriesSummary", "READ_FORMATS", "WRITE_FORMATS"]
