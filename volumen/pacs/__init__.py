"""Studies from where hospitals keep them: query and retrieve from a PACS over DICOMweb and DIMSE.

``volumen.pacs.find("archive", patient_name="Doe*", modality="CT")`` searches (QIDO-RS or C-FIND),
:func:`retrieve` fetches a series into the cache (WADO-RS, C-GET or C-MOVE; a cut transfer leaves no half
series and a rerun resumes), :func:`load` reads ``dicomweb://SERVER/STUDY/SERIES`` with the DICOM reader,
:func:`send` stores what volumen made (STOW-RS or C-STORE). Servers are named in ``servers.toml``
(:mod:`._config`); every protocol's client offers :class:`ArchiveClient`. Libraries: dicomweb-client,
pynetdicom, pydicom; imported when first used.
"""

from ._api import REF_SCHEMES, connect, echo, find, load, make_ref, parse_ref, retrieve, send, series
from ._client import ArchiveClient
from ._config import PROTOCOLS, Server, cache_dir, config_dir, load_servers, resolve_server, servers_file
from ._credentials import unlock
from ._derived import make_capture, make_seg, source_images
from ._records import STUDY_COLUMNS, Query, Series, Studies, Study, printable
from ._series_cache import SeriesCache
from ._thumbnail import thumbnail

__all__ = ["ArchiveClient", "find", "series", "retrieve", "load", "send", "echo", "connect", "parse_ref", "make_ref",
           "thumbnail", "REF_SCHEMES", "PROTOCOLS", "make_seg", "make_capture", "source_images", "Server", "Query",
           "Study", "Studies", "STUDY_COLUMNS", "Series", "SeriesCache", "load_servers", "resolve_server",
           "servers_file", "config_dir", "cache_dir", "unlock", "printable"]
