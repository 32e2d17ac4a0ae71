"""A real Orthanc (Debian's ``orthanc`` and ``orthanc-dicomweb`` packages) for the archive tests.

:class:`Orthanc` starts ``Orthanc CONFIG.json`` as a plain process on free local ports (HTTP and DICOM), with
its storage in a temporary folder, HTTP basic authentication (user ``alice``), the DICOMweb plugin, C-FIND /
C-GET / C-MOVE allowed and volumen's storage SCP registered for C-MOVE. ``stop()`` ends it (and the fixtures
always call it); ``start()`` again brings it back on the same ports and storage. Its own REST API is the
independent truth the tests compare volumen's searches with.
"""

from __future__ import annotations

import ctypes
import json
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import requests

__all__ = ["Orthanc", "missing_reason", "free_port", "USER", "PASSWORD", "AET", "CALLING_AET"]

USER, PASSWORD = "alice", "s3cret-for-tests"
AET, CALLING_AET = "ORTHANC", "VOLUMEN"
_PLUGIN_DIRS = ("/usr/share/orthanc/plugins", "/usr/lib/orthanc")


def _plugin() -> Path | None:
    for d in _PLUGIN_DIRS:
        for p in sorted(Path(d).glob("libOrthancDicomWeb.so*")) if Path(d).is_dir() else []:
            return p
    return None


def missing_reason() -> str | None:
    """Why an Orthanc cannot be started here (None when it can)."""
    if shutil.which("Orthanc") is None:
        return "Orthanc is not installed (Debian package orthanc; `make test` installs it as root)"
    if _plugin() is None:
        return "Orthanc's DICOMweb plugin is not installed (Debian package orthanc-dicomweb; `make test` installs it)"
    return None


def _dying_with_parent():
    """A ``preexec_fn`` (Linux) asking for SIGTERM when the test process dies, even killed (PR_SET_PDEATHSIG), so a
    run stopped by a signal leaves no Orthanc behind; resolved here, the child only calls it (no import after fork)."""
    if not sys.platform.startswith("linux"):
        return None
    prctl = ctypes.CDLL(None, use_errno=True).prctl
    return lambda: prctl(1, signal.SIGTERM)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Orthanc:
    """One Orthanc server in ``folder`` (storage, configuration, log)."""

    def __init__(self, folder: Path, *, store_port: int | None = None, **settings):
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.store_port = store_port or free_port()
        self.settings = settings  # extra Orthanc settings of a test (e.g. DicomCheckCalledAet)
        self.config = self.folder / "orthanc.json"
        self.process: subprocess.Popen | None = None
        self.started = False
        self._configure()

    def _configure(self) -> None:
        """Pick free ports and write the configuration."""
        self.http_port, self.dicom_port = free_port(), free_port()
        config = {
            "Name": "volumen-tests", "StorageDirectory": str(self.folder / "db"),
            "IndexDirectory": str(self.folder / "db"), "Plugins": [str(_plugin())],
            "HttpPort": self.http_port, "DicomPort": self.dicom_port, "DicomAet": AET,
            "RemoteAccessAllowed": False, "AuthenticationEnabled": True, "RegisteredUsers": {USER: PASSWORD},
            "DicomAlwaysAllowFind": True, "DicomAlwaysAllowGet": True, "DicomAlwaysAllowMove": True,
            "DicomModalities": {"volumen": [CALLING_AET, "127.0.0.1", self.store_port]},
            "DicomWeb": {"Enable": True, "Root": "/dicom-web/", "EnableWado": False},
            "SaveJobs": False, "StorageCompression": False, "HttpCompressionEnabled": False,
            "DicomScuTimeout": 5, "DicomAssociationCloseDelay": 0, "ConcurrentJobs": 1,
            "OverwriteInstances": False, "LoadPrivateDictionary": False, **self.settings,
        }
        self.config.write_text(json.dumps(config, indent=1))

    @property
    def base(self) -> str:
        return f"http://127.0.0.1:{self.http_port}"

    @property
    def dicomweb_url(self) -> str:
        return f"{self.base}/dicom-web"

    @property
    def dimse(self) -> str:
        return f"{AET}@127.0.0.1:{self.dicom_port}"

    def start(self, timeout: float = 30.0) -> Orthanc:
        """Start (or restart, on the same ports and storage); a first start retries on new ports when another
        process took one of the free ports in between."""
        for attempt in range(1 if self.started else 3):
            try:
                self._launch(timeout)
                self.started = True
                return self
            except RuntimeError:
                if self.started or attempt == 2:
                    raise
                self._configure()
        return self

    def _launch(self, timeout: float) -> None:
        log = open(self.folder / "orthanc.log", "ab")
        self.process = subprocess.Popen(["Orthanc", str(self.config)], stdout=log, stderr=subprocess.STDOUT,
                                        cwd=self.folder,
                                        preexec_fn=_dying_with_parent())
        log.close()
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.process.poll() is not None:
                raise RuntimeError(f"Orthanc exited with {self.process.returncode}: "
                                   f"{(self.folder / 'orthanc.log').read_text(errors='replace')[-2000:]}")
            try:
                if self.rest("get", "/system", timeout=1).ok:
                    return
            except requests.RequestException:
                pass
            time.sleep(0.05)
        self.stop()
        raise RuntimeError(f"Orthanc did not answer within {timeout} s")

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(20)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(10)
        self.process = None

    # -- its own REST API, the independent truth ------------------------------
    def rest(self, method: str, path: str, **kw) -> requests.Response:
        kw.setdefault("timeout", 30)
        return requests.request(method, self.base + path, auth=(USER, PASSWORD), **kw)

    def upload(self, files) -> int:
        """POST each DICOM file to /instances; the number Orthanc accepted."""
        n = 0
        for f in files:
            r = self.rest("post", "/instances", data=Path(f).read_bytes())
            n += r.ok
        return n

    def find_studies(self, query: dict) -> set[str]:
        """StudyInstanceUIDs of Orthanc's /tools/find at study level (its own matching)."""
        r = self.rest("post", "/tools/find", json={"Level": "Study", "Query": query, "Expand": True})
        r.raise_for_status()
        return {s["MainDicomTags"]["StudyInstanceUID"] for s in r.json()}

    def study_id(self, study_uid: str) -> str | None:
        r = self.rest("post", "/tools/lookup", data=study_uid)
        r.raise_for_status()
        return next((x["ID"] for x in r.json() if x["Type"] == "Study"), None)

    def delete_study(self, study_uid: str) -> None:
        ident = self.study_id(study_uid)
        if ident:
            self.rest("delete", f"/studies/{ident}").raise_for_status()
