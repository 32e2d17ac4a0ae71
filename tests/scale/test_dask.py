"""Dask distributed: a batch of small studies with one worker killed mid-run, resumed; one volume's bricks
drawn on workers equal to the single-process render.

Costs about 20-30 s on 2 cores (a LocalCluster of 2 worker processes that import volumen and load the
compiled kernels from Numba's cache, 49 studies of 40^3 at 48 x 48, a 4-D one and a corrupt one, one worker
restart).
"""

import csv
import os
import signal
import threading
import time

import nibabel as nib
import numpy as np
import pytest
from PIL import Image as PILImage

import volumen
from volumen.core import Camera, Sampling, Scene, TransferFunction, Volume
from volumen.render import render

distributed = pytest.importorskip("distributed", reason="the scale extra (dask[distributed]) is not installed")
pytest.importorskip("zarr", reason="the scale extra (zarr) is not installed")
from volumen.scale import render_distributed, run_batch  # noqa: E402

NSTUDY = 49  # and one corrupt study: 50


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def _studies(tmp_path):
    rows = []
    z, y, x = np.indices((40, 40, 40))
    for n in range(NSTUDY):
        r = 8 + n % 10
        d = np.where((x - 20) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 < r * r, 1000, -1000).astype(np.int16)
        p = tmp_path / f"s{n}.nii.gz"
        volumen.save(Volume(d, modality="CT", units="HU"), p)
        rows.append((f"s{n}", str(p)))
    bad = tmp_path / "corrupt.nii.gz"
    bad.write_bytes(b"\x1f\x8b" + os.urandom(300))
    rows.insert(5, ("corrupt", str(bad)))
    fourd = tmp_path / "fourd.nii.gz"  # drawn from its first volume, which its row's warnings say
    nib.save(nib.Nifti1Image(np.stack([d, d], axis=-1).transpose(2, 1, 0, 3), np.eye(4)), fourd)
    rows.insert(9, ("fourd", str(fourd)))
    man = tmp_path / "manifest.csv"
    with open(man, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "path", "settings", "outputs"])
        for sid, p in rows:
            w.writerow([sid, p, '{"size": [48, 48], "views": [[0, 0], [90, 10]], "preset": "ct-bone"}',
                        "png;slices"])
    return man


def _kill_busy_worker_when_running(client, out, killed):
    """Once some study is finished, SIGKILL a worker that is processing a task (its nanny restarts it)."""
    deadline = time.time() + 120
    while time.time() < deadline and not killed:
        done = list(out.glob("*/axial.png")) if out.exists() else []
        busy = [w for w, keys in client.processing().items() if keys]
        if done and busy:
            pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
            os.kill(pid, signal.SIGKILL)
            killed.append((pid, list(client.processing()[busy[0]])))
            return
        time.sleep(0.05)


def test_batch_survives_a_killed_worker_and_resumes(client, tmp_path):
    man = _studies(tmp_path)
    out = tmp_path / "results"
    killed = []
    t = threading.Thread(target=_kill_busy_worker_when_running, args=(client, out, killed))
    t.start()
    t0 = time.perf_counter()
    rows = run_batch(man, out, client=client, progress=False)
    t.join()
    took = time.perf_counter() - t0
    assert killed and killed[0][1], "a worker was killed while it held a study"
    by_id = {r["id"]: r for r in rows}
    assert by_id["corrupt"]["status"] == "error" and "corrupt.nii.gz" in by_id["corrupt"]["error"]
    for n in range(NSTUDY):
        r = by_id[f"s{n}"]
        assert r["status"] == "ok", r
        for name, size in (("view_0.png", (48, 48)), ("view_1.png", (48, 48)), ("axial.png", (40, 40))):
            with PILImage.open(out / f"s{n}" / name) as im:
                im.load()  # a truncated PNG fails here
                assert im.size == size
    assert not list(out.glob("**/.*"))  # no temporary file left behind
    table = list(csv.DictReader(open(out / "results.csv")))
    assert len(table) == NSTUDY + 2 and {t["status"] for t in table} == {"ok", "error"}
    warned = {t["id"]: t["warnings"] for t in table if t["warnings"]}
    assert list(warned) == ["fourd"] and "read the first volume" in warned["fourd"]
    print(f"{NSTUDY + 2} studies in {took:.1f} s with worker {killed[0][0]} killed holding {killed[0][1]}")
    rerun = {r["id"]: r for r in run_batch(man, out, client=client, progress=False)}
    assert rerun.pop("corrupt")["status"] == "error"
    assert {r["status"] for r in rerun.values()} == {"skipped"}
    assert rerun["fourd"]["warnings"] == warned["fourd"]  # a skipped study keeps what its reader warned of


def test_a_study_records_what_its_reader_warned_of(tmp_path):
    """A 4-D NIfTI holding NaN: the study is drawn (its first volume, the NaN as 0) and its row's ``warnings``
    says both, as the commands say them on the terminal; results.csv has the column."""
    import nibabel as nib

    from volumen.scale._batch import RESULT_FIELDS, run_study

    data = np.random.default_rng(3).random((10, 11, 12, 2)).astype(np.float32)
    data[1, 1, 1, 0] = np.nan
    nib.save(nib.Nifti1Image(data, np.eye(4)), tmp_path / "dwi.nii.gz")
    row = {"id": "dwi", "path": str(tmp_path / "dwi.nii.gz"), "settings": "", "outputs": ["slices"]}
    res = run_study(row, tmp_path / "out")
    assert res["status"] == "ok" and (tmp_path / "out" / "dwi" / "axial.png").exists()
    said = res["warnings"].split(" | ")
    assert len(said) == 2 and "first volume" in said[0] and "1 of 1320 voxels are NaN" in said[1], said
    assert "warnings" in RESULT_FIELDS


@pytest.mark.parametrize("mode", ["composite", "mip"])
def test_distributed_bricks_equal_single_process(client, tmp_path, mode):
    z, y, x = np.indices((48, 40, 36))
    rng = np.random.default_rng(1)
    d = (900 * np.exp(-((x - 18) ** 2 + (y - 20) ** 2 + (z - 24) ** 2) / 150.0) + rng.normal(0, 25, x.shape))
    v = Volume(d.astype(np.int16), spacing=(1.0, 0.8, 1.2))
    p = tmp_path / "one.ome.zarr"
    volumen.save(v, p, chunks=16)
    tf = TransferFunction.window_level(600, 450, opacity=(0.0, 0.5))
    scene = Scene(volume=v, transfer=tf, mode=mode,
                  sampling=Sampling(samples_per_voxel=1.5, early_termination=1.0, seed=7, adaptive=False))  # no carry
    # between workers; full rate, as bricks sample
    cam = Camera.orbit(v, azimuth=40, elevation=25)
    ref = render(scene, cam, (64, 56))
    out = render_distributed(client, p, scene, cam, (64, 56), brick=16)
    assert out.stats["bricks_drawn"] > 1
    np.testing.assert_allclose(out.rgba, ref.rgba, atol=1e-5)
    if mode == "mip":
        np.testing.assert_allclose(out.value, ref.value, atol=1e-2)  # HU
