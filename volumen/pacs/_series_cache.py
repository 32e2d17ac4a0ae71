"""The cache of retrieved series: whole series only, under their final name; a partial one under another.

Layout under :func:`volumen.pacs.cache_dir` ``/archives``::

    SERVER/STUDY_UID/SERIES_UID/SOP_UID.dcm          a complete series (only ever made by a rename)
    SERVER/STUDY_UID/.SERIES_UID.partial/SOP_UID.dcm  instances fetched so far (each whole: written as
                                                       .tmp and renamed), kept for a rerun to resume

``SERVER`` is the server's name made safe for a file name. UIDs are checked to be digits and dots before
they name a folder.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
from dataclasses import dataclass
from pathlib import Path

from ._config import cache_dir
from ._records import check_uid

__all__ = ["SeriesCache"]

_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")


def _server_key(name: str) -> str:
    safe = _UNSAFE.sub("_", name).strip("._")[:40]
    if safe == name:
        return safe
    return f"{safe}-{hashlib.sha1(name.encode()).hexdigest()[:8]}"


@dataclass(frozen=True)
class SeriesCache:
    """Where one series of one server lives in the cache (``root``: default ``cache_dir() / "archives"``)."""

    server: str
    study_uid: str
    series_uid: str
    root: Path | None = None

    def __post_init__(self):
        check_uid(self.study_uid, "study UID")
        check_uid(self.series_uid, "series UID")

    @property
    def folder(self) -> Path:
        """The complete series (exists only once every instance is in)."""
        root = Path(self.root) if self.root is not None else cache_dir() / "archives"
        return root / _server_key(self.server) / self.study_uid / self.series_uid

    @property
    def partial(self) -> Path:
        """The instances fetched so far."""
        return self.folder.with_name(f".{self.series_uid}.partial")

    def complete(self) -> bool:
        return self.folder.is_dir()

    def present(self) -> set[str]:
        """SOP Instance UIDs already whole in the partial folder."""
        if not self.partial.is_dir():
            return set()
        return {p.name[:-4] for p in self.partial.iterdir() if p.name.endswith(".dcm")}

    def write(self, dataset) -> Path:
        """Write one instance into the partial folder: ``.tmp`` first, renamed when whole."""
        uid = check_uid(str(dataset.SOPInstanceUID), "SOP instance UID")
        self.partial.mkdir(parents=True, exist_ok=True)
        final = self.partial / f"{uid}.dcm"
        tmp = final.with_name(final.name + ".tmp")
        try:
            dataset.save_as(tmp, enforce_file_format=True)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
        os.replace(tmp, final)
        return final

    def keep_only(self, uids: set[str]) -> None:
        """Drop fetched instances the server no longer lists (deleted since an earlier, cut retrieve)."""
        for uid in self.present() - set(uids):
            (self.partial / f"{uid}.dcm").unlink()

    def finish(self) -> Path:
        """The partial folder becomes the series (an older copy, if any, is replaced)."""
        for stale in self.partial.glob("*.tmp"):
            stale.unlink()
        if self.folder.exists():
            shutil.rmtree(self.folder)
        os.replace(self.partial, self.folder)
        return self.folder

    def forget(self) -> None:
        """Remove the series and what was fetched of it."""
        for p in (self.folder, self.partial):
            if p.exists():
                shutil.rmtree(p)
