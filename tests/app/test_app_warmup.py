"""The app's background warm-up (``volumen.app._warmup``): started once per kind of volume, stopped with the window."""

from __future__ import annotations

import multiprocessing as mp
import time

from volumen.app._view_picture import FrameJob
from volumen.app._warmup import VARIANTS, Warmup, variants
from volumen.core import Camera, Scene, Shading, TransferFunction


def _job(vol, device="cpu"):
    scene = Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"), shading=Shading(mode="headlight"))
    return FrameJob(scene=scene, camera=Camera.orbit(vol), size=(32, 32), device=device)


def test_the_other_kernels_warm_once_per_kind_and_stop_with_the_window(head64, monkeypatch):
    monkeypatch.delenv("VOLUMEN_WARM", raising=False)
    job = _job(head64)
    jobs = variants(job)
    assert len(jobs) == len(VARIANTS) - 1  # all but the picture's own
    assert ("composite", "headlight") not in {(s.mode, s.shading.mode) for s, _ in jobs}
    assert {s.shading.mode for s, _ in jobs} >= {"shadows", "scattering", "phong", "none"}
    w = Warmup()
    assert not w.after(_job(head64, device="gl"))  # only the CPU's kernels
    assert w.after(job) and w.running
    assert not w.after(job)  # one warm-up per kind of volume
    assert w._wanted(_job(head64.with_data(head64.data.astype("float32")))) == w._wanted(job)  # one kind: int16
    deadline = time.monotonic() + 5.0
    while not mp.active_children() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert mp.active_children()  # the child runs
    time.sleep(1.0)
    w.stop()  # the window closes while the child compiles
    assert not w.running  # the thread ended within stop's own wait
    deadline = time.monotonic() + 5.0
    while mp.active_children() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not mp.active_children()  # the child is gone
    assert not w.after(job)  # and none starts after closing


def test_off_by_environment(head64, monkeypatch):
    monkeypatch.setenv("VOLUMEN_WARM", "0")
    assert not Warmup().after(_job(head64))
