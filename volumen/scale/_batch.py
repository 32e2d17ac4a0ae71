"""Batch rendering of many studies on a Dask distributed cluster: resumable, atomic, errors recorded.

Manifest: a CSV with columns ``id`` (a folder name), ``path`` (a volume file,
folder, OME-Zarr, or ``phantom:NAME``), ``settings`` (a JSON object, inline or
the path of a ``.json`` file; may be empty) and ``outputs`` (``;``-separated
kinds, default ``png``):

- ``png``: one picture per view (``view_<n>.png``) of :func:`~volumen.render.render_volume`;
  settings ``views`` (list of ``[azimuth, elevation]``, default ``[[0, 0], [90, 0]]``),
  ``size`` (``[w, h]``, default ``[256, 256]``), ``mode``, ``preset``, ``shading``;
- ``slices``: the middle axial slice (``axial.png``), settings ``window``;
- ``mesh``: the isosurface at settings ``iso`` (``mesh.ply``);
- ``mp4``: an orbit of settings ``frames`` pictures (default 24, ``orbit.mp4``).

Every output is written to a temporary name in its folder (``.tmp-*``) and
renamed into place, so an output either exists whole or not at all (the
temporary files a killed worker leaves are removed when the batch ends). A re-run skips the
studies whose outputs all exist. A study whose task dies with its worker is
rescheduled by Dask on another worker (up to ``distributed.scheduler.allowed-failures``);
an error in a study (unreadable file, bad settings) is caught and recorded in
``results.csv`` (id, status ``ok | skipped | error``, seconds, outputs, error,
warnings) and the batch goes on. ``warnings`` holds what the reader warned of in a study it read (a 4-D
file's first volume drawn, NaN replaced, uneven slices: ``meta["warnings"]`` joined by ``" | "``), as the
``volumen`` commands say it on the terminal.
"""

from __future__ import annotations

import csv
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = ["read_manifest", "run_study", "run_batch", "study_outputs", "OUTPUT_KINDS"]

OUTPUT_KINDS = ("png", "slices", "mesh", "mp4")
RESULT_FIELDS = ("id", "status", "seconds", "outputs", "error", "warnings")
TMP_PREFIX = ".tmp-"  #: outputs being written; what a killed worker leaves is swept when the batch ends


def read_manifest(path) -> list[dict]:
    """The manifest's rows (dicts with ``id``, ``path``, ``settings`` (dict), ``outputs`` (list))."""
    from ..errors import VolumeReadError

    p = Path(path)
    with open(p, newline="") as f:
        rows = list(csv.DictReader(f))
    out = []
    for n, r in enumerate(rows, start=2):
        if not r.get("id") or not r.get("path"):
            raise VolumeReadError(p, f"line {n}: every study needs an id and a path")
        kinds = [k.strip() for k in (r.get("outputs") or "png").split(";") if k.strip()]
        bad = [k for k in kinds if k not in OUTPUT_KINDS]
        if bad:
            raise VolumeReadError(p, f"line {n}: unknown output(s) {bad}; choose from {list(OUTPUT_KINDS)}")
        out.append({"id": r["id"].strip(), "path": r["path"].strip(), "settings": (r.get("settings") or "").strip(),
                    "outputs": kinds})
    return out


def _settings(text: str) -> dict:
    if not text:
        return {}
    if text.lstrip().startswith("{"):
        return json.loads(text)
    return json.loads(Path(text).read_text())


def study_outputs(row: dict, out_dir) -> list[Path]:
    """The files a study writes (known from the manifest alone, so finished studies are found without reading)."""
    d = Path(out_dir) / row["id"]
    try:
        views = len(_settings(row["settings"]).get("views", [[0, 0], [90, 0]]))
    except (ValueError, OSError):
        views = 1
    names = {"png": [f"view_{n}.png" for n in range(views)], "slices": ["axial.png"], "mesh": ["mesh.ply"],
             "mp4": ["orbit.mp4"]}
    return [d / name for k in row["outputs"] for name in names[k]]


def _atomic(path: Path, write) -> None:
    """``write(tmp)`` to a temporary file beside ``path``, then rename it into place."""
    fd, tmp = tempfile.mkstemp(prefix=f"{TMP_PREFIX}{path.stem}-", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _load(path: str):
    from ..io import load

    if path.startswith("phantom:"):
        from ..data import phantom

        return phantom(path.split(":", 1)[1])
    return load(path)


def _render_kw(s: dict) -> dict:
    kw = {k: s[k] for k in ("mode", "preset", "shading", "samples_per_voxel") if k in s}
    kw["size"] = tuple(s.get("size", (256, 256)))
    return kw


def _write_outputs(vol, row, s, files) -> None:
    from PIL import Image as PILImage

    from ..core import slice_image
    from ..render import render_volume

    kw = _render_kw(s)
    for f in files:
        if f.exists():
            continue
        if f.name.startswith("view_"):
            az, el = s.get("views", [[0, 0], [90, 0]])[int(f.stem.split("_")[1])]
            img = render_volume(vol, azimuth=az, elevation=el, **kw)
            _atomic(f, lambda t, img=img: img.save(t))
        elif f.name == "axial.png":
            sl = slice_image(vol, "axial", window=s.get("window"))
            _atomic(f, lambda t, sl=sl: PILImage.fromarray(sl).save(t, format="PNG"))
        elif f.name == "mesh.ply":
            from ..surface import extract_mesh, write_mesh

            mesh = extract_mesh(vol, float(s["iso"]) if "iso" in s else None)
            _atomic(f, lambda t, mesh=mesh: write_mesh(mesh, t))
        elif f.name == "orbit.mp4":
            import imageio.v3 as iio

            n = int(s.get("frames", 24))
            frames = np.stack([render_volume(vol, azimuth=360.0 * i / n, **kw).to_uint8() for i in range(n)])
            _atomic(f, lambda t, frames=frames: iio.imwrite(t, frames, extension=".mp4", fps=12))


def run_study(row: dict, out_dir) -> dict:
    """Render one study's missing outputs; never raises for the study's own errors (they are returned)."""
    t0 = time.perf_counter()
    files = study_outputs(row, out_dir)
    res = {"id": row["id"], "outputs": ";".join(f.name for f in files), "error": "", "warnings": ""}
    try:
        files[0].parent.mkdir(parents=True, exist_ok=True)
        vol = _load(row["path"])
        res["warnings"] = " | ".join(vol.meta.get("warnings", []))[:500]
        _write_outputs(vol, row, _settings(row["settings"]), files)
        res["status"] = "ok"
    except Exception as exc:  # noqa: BLE001  (one study's failure, whatever it is, is recorded; the batch goes on)
        res["status"] = "error"
        res["error"] = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"[:500]
    res["seconds"] = round(time.perf_counter() - t0, 3)
    return res


def _write_results(out_dir: Path, results: dict) -> None:
    def write(t):
        with open(t, "w", newline="") as f:
            w = csv.DictWriter(f, RESULT_FIELDS)
            w.writeheader()
            for r in results.values():
                w.writerow({k: r.get(k, "") for k in RESULT_FIELDS})

    _atomic(out_dir / "results.csv", write)


def _earlier_results(out: Path) -> dict:
    """The rows of an earlier run's results.csv in ``out`` by study id (none where there is none)."""
    try:
        with open(out / "results.csv", newline="") as f:
            return {r["id"]: r for r in csv.DictReader(f)}
    except OSError:
        return {}


def run_batch(manifest, out_dir, *, client=None, scheduler: str | None = None, workers: int = 2,
              progress: bool = True) -> list[dict]:
    """Render every study of ``manifest`` into ``out_dir`` on a Dask cluster; returns the results' rows.

    ``client``: a ``distributed.Client`` to use; else one connected to ``scheduler`` (an address), else a
    ``LocalCluster`` of ``workers`` single-threaded worker processes, closed at the end.
    """
    from tqdm import tqdm

    from ..errors import require

    require("distributed", "batch rendering on Dask")
    from distributed import Client, LocalCluster, as_completed

    rows = read_manifest(manifest) if not isinstance(manifest, list) else manifest
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results = {r["id"]: {"id": r["id"], "status": "pending"} for r in rows}
    earlier = _earlier_results(out)
    todo = []
    for r in rows:
        files = study_outputs(r, out)
        if all(f.exists() for f in files):  # drawn by an earlier run: its reader's warnings are kept
            results[r["id"]] = {"id": r["id"], "status": "skipped", "seconds": 0, "error": "",
                                "outputs": ";".join(f.name for f in files),
                                "warnings": earlier.get(r["id"], {}).get("warnings", "")}
        else:
            todo.append(r)
    cluster = None
    if client is None:
        if scheduler is None:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(scheduler or cluster)
    try:
        futs = [client.submit(run_study, r, str(out), key=f"study-{r['id']}", pure=False) for r in todo]
        ids = {f.key: r["id"] for f, r in zip(futs, todo, strict=True)}
        for fut in tqdm(as_completed(futs), total=len(futs), desc="studies", disable=not progress):
            try:
                res = fut.result()
            except Exception as exc:  # noqa: BLE001  (a task Dask gave up on, e.g. KilledWorker: recorded)
                res = {"id": ids[fut.key], "status": "error", "seconds": "", "outputs": "",
                       "error": f"{type(exc).__name__}: {exc}"[:500]}
            results[res["id"]] = res
            _write_results(out, results)
    finally:
        if cluster is not None:
            client.close()
            cluster.close()
    for stale in out.glob(f"*/{TMP_PREFIX}*"):  # every task is over: these are from workers killed mid-write
        stale.unlink(missing_ok=True)
    _write_results(out, results)
    return list(results.values())
