"""What the test archive holds: four made studies (multi-slice CT and MR series, written with pydicom through
``tests/io/dicom_factory.py``) and every file of pydicom's own test data that Orthanc accepts.

``running_archive`` (the ``archive`` fixture of ``tests/conftest.py``) starts one Orthanc per test session
(per worker), uploads them through Orthanc's REST API (not through volumen) and stops it at the end.
``write_servers_toml`` names it ``archive`` in a ``servers.toml`` for volumen.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from tests.io.dicom_factory import new_uid, stack_positions, write_series
from tests.pacs.orthanc_server import AET, CALLING_AET, USER, Orthanc, missing_reason

__all__ = ["Archive", "MadeSeries", "STUDIES", "running_archive", "write_servers_toml", "pydicom_files",
           "PASSWORD_ENV"]

PASSWORD_ENV = "VOLUMEN_TEST_ARCHIVE_PASSWORD"

#: (key, patient name, patient ID, study date, description, accession, [(modality, slices, description)])
STUDIES = (
    ("chest", "Doe^Jane", "PAT-001", "20240102", "CT chest", "ACC-1", [("CT", 8, "axial 2 mm"), ("CT", 3, "scout")]),
    ("abdomen", "Roe^Richard", "PAT-002", "20230615", "CT abdomen", "ACC-2", [("CT", 5, "portal venous")]),
    ("head", "Doe^John", "PAT-003", "20241120", "MR head", "ACC-3", [("MR", 4, "t1")]),
    # what "Doe?Jane" and "CT?chest" also match: a search for Doe^Jane or "CT chest" must not find it
    ("lookalike", "Doe Jane", "PAT-004", "20220301", "CT-chest", "ACC-4", [("CT", 2, "axial")]),
)


@dataclass
class MadeSeries:
    study_uid: str
    series_uid: str
    folder: Path
    modality: str
    n: int


@dataclass
class Archive:
    """The running server and what was uploaded to it."""

    server: Orthanc
    series: dict[str, list[MadeSeries]] = field(default_factory=dict)   # study key -> its series
    study_uids: dict[str, str] = field(default_factory=dict)           # study key -> StudyInstanceUID

    @property
    def ct(self) -> MadeSeries:
        """The 8-slice CT series every retrieval test fetches."""
        return self.series["chest"][0]


def pydicom_files() -> list[Path]:
    """pydicom's installed test files (nothing downloaded)."""
    import pydicom

    data = Path(pydicom.__file__).parent / "data" / "test_files"
    return sorted(p for p in data.rglob("*") if p.is_file() and p.suffix.lower() not in (".py", ".pyc", ".json",
                                                                                          ".txt", ".gz", ".icc"))


def make_studies(folder: Path) -> tuple[dict, dict]:
    """Write the studies of :data:`STUDIES` under ``folder``; (series by study key, study UIDs by key)."""
    rng = np.random.default_rng(28)
    made, uids = {}, {}
    for key, name, pid, date, desc, acc, series in STUDIES:
        study_uid = new_uid(f"pacs-study-{key}")
        uids[key] = study_uid
        made[key] = []
        for k, (modality, n, sdesc) in enumerate(series):
            series_uid = new_uid(f"pacs-series-{key}-{k}")
            raw = rng.integers(-1000, 2000, size=(n, 24, 20)).astype(np.int16)
            out = folder / key / str(k)
            write_series(out, raw, row_dir=(1, 0, 0), col_dir=(0, 1, 0), series_uid=series_uid, description=sdesc,
                         modality=modality, positions=stack_positions((-10.0, -12.0, 30.0), (1, 0, 0), (0, 1, 0),
                                                                      np.arange(n) * 2.0),
                         patient={"PatientName": name, "PatientID": pid, "StudyInstanceUID": study_uid,
                                  "StudyDate": date, "StudyDescription": desc, "AccessionNumber": acc,
                                  "SeriesNumber": k + 1}, prefix=f"{key}{k}_")
            made[key].append(MadeSeries(study_uid, series_uid, out, modality, n))
    return made, uids


def running_archive(tmp_path_factory, name: str = "archive", *, with_pydicom: bool = True, **settings):
    """Generator of a fixture: an Orthanc (``settings``: extra Orthanc settings) holding the made studies and,
    ``with_pydicom``, pydicom's files; stopped at the end. Skips, saying why, without Orthanc."""
    reason = missing_reason()
    if reason:
        pytest.skip(reason)
    folder = tmp_path_factory.mktemp(name)
    made, uids = make_studies(folder / "upload")
    server = Orthanc(folder / "orthanc", **settings).start()
    try:
        files = [p for series in made.values() for s in series for p in sorted(s.folder.iterdir())]
        assert server.upload(files) == len(files)
        if with_pydicom:
            server.upload(pydicom_files())
        yield Archive(server, made, uids)
    finally:
        server.stop()


def write_servers_toml(config_home: Path, server: Orthanc, name: str = "archive") -> Path:
    """``config_home/volumen/servers.toml`` naming ``server`` (DICOMweb and DIMSE, password from the
    environment variable :data:`PASSWORD_ENV`); readable by its owner only."""
    path = config_home / "volumen" / "servers.toml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        f'[servers.{name}]\nurl = "{server.dicomweb_url}"\nusername = "{USER}"\npassword_env = "{PASSWORD_ENV}"\n'
        f'ae_title = "{AET}"\nhost = "127.0.0.1"\nport = {server.dicom_port}\ncalling_ae_title = "{CALLING_AET}"\n'
        f"store_port = {server.store_port}\n", encoding="utf-8")
    os.chmod(path, 0o600)
    return path
