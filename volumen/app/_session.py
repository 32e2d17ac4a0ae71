"""Session files: everything the user set up, as JSON, written atomically.

A session is a superset of the settings file of ``volumen render
--save-settings`` (``version``, ``scene``, ``camera``, ``size``,
``background``, ``device``, ``technique``), so ``volumen render --settings
session.json -o out.png`` renders the session's 3D view. The application's own
state sits under ``"app"``: brightness, stereo, crosshair, slice window, mesh
display, and the endoscopy path (start, end, centerline). The measurements (rulers, regions: ``volumen.measure``)
sit under ``"measurements"``, as in the browser page's state, and ``volumen measure export`` reads them there.

The data is named by ``scene.volume`` (a path, or ``phantom:NAME`` with an
optional ``?size=N``); :func:`resolve_volume` loads it.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import numpy as np

from ..core import Camera, Scene, Window
from ..errors import MeasurementError, VolumenError
from ..measure import SESSION_KEY, check_scan, session_measurements

__all__ = ["SESSION_VERSION", "SessionError", "session_dict", "apply_session", "save_session", "load_session",
           "resolve_volume", "phantom_ref", "series_ref", "split_series_ref", "load_or_list", "write_atomic"]

SESSION_VERSION = 1


class SessionError(VolumenError, ValueError):
    """A session file that cannot be read or applied; the message names the file and the problem."""

    def __init__(self, path, problem: str):
        self.path = None if path is None else str(path)
        self.problem = problem
        super().__init__(f"{self.path}: {problem}" if self.path else problem)


def phantom_ref(name: str, size: int | None = None) -> str:
    """The volume reference of a built-in phantom (``phantom:head`` or ``phantom:head?size=64``)."""
    return f"phantom:{name}" if size is None else f"phantom:{name}?size={int(size)}"


def resolve_volume(ref: str):
    """Load the volume named by a reference: ``phantom:NAME[?size=N]``, a file / DICOM folder path,
    ``FOLDER?series=UID`` for one series of a DICOM folder, or ``dicomweb://SERVER/STUDY/SERIES`` (retrieved
    into the cache unless it is there already).

    Raises
    ------
    VolumeReadError
        (or a subclass) when a file cannot be read; ValueError for a bad phantom reference.
    """
    if ref.startswith("phantom:"):
        from ..data import phantom

        name, _, query = ref[len("phantom:"):].partition("?")
        kw = {}
        for part in filter(None, query.split("&")):
            key, _, val = part.partition("=")
            if key != "size":
                raise ValueError(f"unknown phantom option {key!r} in {ref!r}; valid: size")
            kw["size"] = int(val)
        return phantom(name, **kw)
    if ref.startswith(("dicomweb://", "dimse://")):
        from ..pacs import load as load_archived

        return load_archived(ref)
    from ..io import load

    path, series = split_series_ref(ref)
    return load(path) if series is None else load(path, series=series)


def load_or_list(ref: str):
    """The volume of ``ref``, or ``(series summaries, notes)`` when it is a DICOM folder of several
    series (for the series chooser); other failures raise as :func:`resolve_volume` does."""
    from ..errors import MultipleSeriesError
    from ..io import list_series

    try:
        return resolve_volume(ref)
    except MultipleSeriesError:
        notes: list[str] = []
        return list_series(split_series_ref(ref)[0], notes), notes


_SERIES = "?series="


def series_ref(path: str, series: str | None) -> str:
    """The reference of DICOM series ``series`` (a SeriesInstanceUID) in folder ``path``: ``PATH?series=UID``."""
    return str(path) if series is None else f"{path}{_SERIES}{series}"


def split_series_ref(ref: str) -> tuple[str, str | None]:
    """``(path, SeriesInstanceUID or None)`` of a reference made by :func:`series_ref` (a path that
    exists as written is never split)."""
    import os

    path, sep, series = ref.rpartition(_SERIES)
    if not sep or os.path.exists(ref):
        return ref, None
    return path, series


def session_dict(state, size: tuple[int, int], endoscopy: dict | None = None) -> dict:
    """The JSON-ready session of an :class:`~volumen.app._state.AppState` with a 3D view of ``size``."""
    if state.camera is None:
        raise SessionError(None, "nothing is loaded: there is no session to save")
    return {
        "version": SESSION_VERSION,
        "kind": "volumen-session",
        "scene": state.scene.to_dict(),
        "camera": state.camera.to_dict(),
        "size": [int(size[0]), int(size[1])],
        "background": list(state.background),
        "device": state.device,
        "technique": state.technique.to_dict(),
        "app": {
            "brightness": float(state.brightness),
            "stereo": state.stereo.to_dict(),
            "crosshair": [float(v) for v in state.crosshair],
            "window": [float(state.window.level), float(state.window.width)],
            "mesh_display": state.mesh_display,
            "endoscopy": endoscopy,
        },
        SESSION_KEY: state.measurements.to_dicts(),
    }


def apply_session(state, d: dict, volume) -> dict:
    """Put session ``d`` into ``state`` with the already loaded ``volume``; returns the ``endoscopy`` entry.

    Raises :class:`SessionError` for a malformed session (unknown fields, bad values), and
    :class:`~volumen.errors.MeasurementError` for measurements made on another scan than ``volume``; either way
    before ``state`` changes.
    """
    from ._stereo import Stereo

    try:
        scene = Scene.from_dict(d["scene"], volume=volume)
        camera = Camera.from_dict(d["camera"])
        app = d.get("app", {})
        stereo = Stereo.from_dict(app.get("stereo", {}))
        window = Window(*app["window"]) if "window" in app else None
        background = tuple(float(v) for v in d.get("background", (0, 0, 0)))
        how = _technique(d)
        measurements = session_measurements(d)
    except MeasurementError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise SessionError(None, f"not a valid session: {exc}") from None
    check_scan(measurements, volume)  # before anything changes: a refused session leaves the state as it was
    with state.batch():
        state.set_volume(volume, scene.volume_ref, transfer=scene.transfer, camera=camera)
        state.update_scene(**{k: getattr(scene, k) for k in ("lights", "mode", "shading", "sampling", "clipping",
                                                              "isosurface")})
        state.set_display(**how, brightness=float(app.get("brightness", 1.0)),
                          background=background, stereo=stereo,
                          mesh_display=app.get("mesh_display", "hidden"))
        if "crosshair" in app:
            state.set_crosshair(np.asarray(app["crosshair"], float))
        if window is not None:
            state.set_window(window)
        state.set_measurements(measurements)
    return app.get("endoscopy")


def _technique(d: dict) -> dict:
    """``device`` and ``technique`` of a session (volumen 0.1 kept a backend name as ``app.technique``)."""
    from ..render import Technique, legacy_backend, resolve_device

    if "technique" in d:
        technique = Technique.from_dict(d["technique"])
        return {"device": d.get("device") or resolve_device(None, technique.name), "technique": technique}
    device, technique = legacy_backend(d.get("app", {}).get("technique", "cpu"))
    return {"device": device, "technique": technique}


def write_atomic(path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder and ``os.replace``.

    A crash or a full disk leaves either the old file or the new one, never half of one.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def save_session(path, d: dict) -> None:
    """Write session ``d`` to ``path`` atomically (:func:`write_atomic`)."""
    try:
        write_atomic(path, json.dumps(d, indent=2))
    except OSError as exc:
        raise SessionError(path, f"cannot write the session: {exc.strerror or exc}") from None


def load_session(path) -> dict:
    """Read and check a session (or ``volumen render`` settings) file; raises :class:`SessionError`."""
    try:
        d = json.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as exc:
        raise SessionError(path, f"cannot read the session: {exc.strerror or exc}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SessionError(path, f"not a JSON session file ({exc})") from None
    if not isinstance(d, dict) or d.get("version") != SESSION_VERSION or not {"scene", "camera"} <= set(d):
        raise SessionError(path, f"not a volumen session (version {SESSION_VERSION} with 'scene' and 'camera')")
    if not d["scene"].get("volume"):
        raise SessionError(path, "the session names no data (scene.volume is empty)")
    return d
