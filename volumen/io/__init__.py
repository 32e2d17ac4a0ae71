"""Reading and writing volume files (one module per family of formats).

Libraries used: pydicom (DICOM), nibabel (NIfTI), pynrrd (NRRD headers), SimpleITK
(MetaImage writing); MetaImage, NRRD data, .npy/.npz containers and VTK legacy
structured points are parsed here, every header value checked first (``_header_limits``).
The readers' fuzzer lives outside the package (``tools/fuzz/io``, ``make fuzz``).
"""

from ._api import READ_FORMATS, WRITE_FORMATS, detect_format, load, save
from ._chunk_cache import ChunkCache
from ._chunked import ChunkedArray
from ._dicom_listing import SeriesSummary, list_series
from ._environment_maps import read_environment
from ._label_files import MASK_SUFFIXES, labels_on_grid, load_labels, resample_labels
from ._labels_tables import read_names_table
from ._zarr import Level, open_levels

__all__ = ["load", "save", "load_labels", "labels_on_grid", "resample_labels", "read_names_table",
           "MASK_SUFFIXES", "detect_format", "list_series", "SeriesSummary", "READ_FORMATS", "WRITE_FORMATS",
           "ChunkedArray", "ChunkCache", "open_levels", "Level", "read_environment"]
