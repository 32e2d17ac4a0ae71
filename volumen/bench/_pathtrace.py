"""``volumen bench pathtrace``: the path tracer's error against a reference, denoised and raw, and its speed.

Cases: VMTK's aorta (``aorta.mha`` where it is found, in its own units; the CT presets shifted by +1000) and the
head phantom, each with the cinematic preset and the studio rig (no lights given: the default scene of
``volumen render --shading pathtrace``). For each, one progressive path tracer accumulates
``REFERENCE`` samples per pixel in other random streams (two halves, seeds 1 and 2: half their difference estimates
the reference's own error, ``reference's own``) as the reference, and a second one (seed 0) gives the pictures
compared with it (linear radiance, premultiplied, each pixel the mean over its area as the path tracer draws it;
mean absolute error over the pixels the volume covers):

* ``16 dn``: 16 samples, denoised (Intel Open Image Denoise, the noise-free albedo and normal of
  ``raycast._features``, the samples' local mean kept); ``bias``: its mean minus the reference's mean over the same
  pixels;
* ``16 raw``, ``256 raw``: 16 and 256 samples, not denoised;
* equal time: the raw picture with as many samples as the 16 denoised ones' time (tracing plus denoising) buys
  (``raw same time``), and the ratio of the denoised error to it (``dn / raw``).

Speed: samples per pixel per second on the 366x303x336 resampling of the aorta at 782x415 (``bench render``'s
largest data set), the number before the path tracer (0.83). Machine load (``os.getloadavg``)
is printed with the table: the machine is shared.
"""

from __future__ import annotations

import os
import time

import numpy as np

from ._table import Table

__all__ = ["bench_pathtrace"]

#: samples per pixel of the reference pictures
REFERENCE = 4096
FULL = {"size": (160, 160), "reference": REFERENCE, "speed_size": (782, 415), "speed_shape": (366, 303, 336)}
QUICK = {"size": (32, 32), "reference": 256, "speed_size": (64, 48), "speed_shape": (48, 40, 44)}


def _cases(quick: bool):
    """name -> (scene, camera) of the compared cases."""
    from volumen.core import Camera, Scene, Shading, TransferFunction
    from volumen.data import phantom

    from ._datasets import AORTA_OFFSET, aorta_path, upsampled_aorta

    out = {}
    head = phantom("head", size=(40, 48, 48) if quick else (96, 112, 112))
    out["head phantom, ct-cinematic-bone"] = (Scene(volume=head, transfer=TransferFunction.preset(
        "ct-cinematic-bone"), shading=Shading(mode="pathtrace")), Camera.orbit(head, azimuth=-30, elevation=15))
    if aorta_path() is not None:
        vol = upsampled_aorta((96, 80, 88) if quick else (157, 393, 34))
        tf = TransferFunction.preset("ct-cinematic-vessels").shifted(AORTA_OFFSET)
        out["VMTK aorta, ct-cinematic-vessels"] = (Scene(volume=vol, transfer=tf, shading=Shading(mode="pathtrace")),
                                                  Camera.orbit(vol, view="left", zoom=1.6))
    return out


def _error(img, ref, cover):
    d = img[..., :3].astype(np.float64) - ref[..., :3]
    return float(np.abs(d)[cover].mean()), float(d[cover].mean())


def _compare(scene, cam, size, reference, progress):
    """One case's row: errors of 16 denoised, 256 raw and raw at equal time against the reference."""
    from volumen.core import Sampling
    from volumen.render import PathTracer

    t = time.perf_counter()
    halves = []
    for seed in (1, 2):
        ref_pt = PathTracer(scene.with_(sampling=Sampling(seed=seed)), cam, size)
        while ref_pt.spp < reference // 2:
            ref_pt.add(min(256, reference // 2 - ref_pt.spp))
        halves.append(ref_pt.image(denoised=False).rgba.astype(np.float64))
    ref = 0.5 * (halves[0] + halves[1])
    progress(f"  reference: {reference} spp in {time.perf_counter() - t:.1f} s")
    cover = ref[..., 3] > 0.05
    e_ref = 0.5 * _error(halves[0], halves[1], cover)[0]
    pt = PathTracer(scene, cam, size)
    t_trace = pt.add(16)
    t = time.perf_counter()
    dn = pt.image(denoised=True).rgba
    t_dn = t_trace + time.perf_counter() - t
    e_dn, bias = _error(dn, ref, cover)
    e_raw16, _ = _error(pt.image(denoised=False).rgba, ref, cover)
    pt.add(256 - 16)
    e_raw, _ = _error(pt.image(denoised=False).rgba, ref, cover)
    per_spp = pt.seconds / pt.spp
    n_eq = max(int(t_dn / per_spp), 1)
    eq = PathTracer(scene, cam, size)
    eq.add(n_eq)
    e_eq, _ = _error(eq.image(denoised=False).rgba, ref, cover)
    return {"e_ref": e_ref, "e_raw16": e_raw16, "e_dn16": e_dn, "e_raw256": e_raw, "bias": bias, "spp_eq": n_eq,
            "e_raw_eq": e_eq, "ratio": e_dn / e_eq, "dn_s": t_dn,
            "ok": e_dn <= e_raw and e_dn <= e_eq / 3 and abs(bias) <= 0.005}


def _speed(shape, size, progress):
    """Samples per pixel per second on the aorta resampled to ``shape`` (x, y, z) at ``size``, studio rig."""
    from volumen.core import Camera, Scene, Shading, TransferFunction
    from volumen.render import PathTracer

    from ._datasets import AORTA_OFFSET, aorta_path, upsampled_aorta

    if aorta_path() is None:
        return None
    vol = upsampled_aorta(shape)
    scene = Scene(volume=vol, transfer=TransferFunction.preset("ct-cinematic-vessels").shifted(AORTA_OFFSET),
                  shading=Shading(mode="pathtrace"))
    pt = PathTracer(scene, Camera.orbit(vol), size)
    pt.add(1)  # compiled, coverage computed
    n = 8
    dt = pt.add(n)
    progress(f"  speed: {n} spp in {dt:.2f} s")
    return n / dt


def bench_pathtrace(*, quick: bool = False, progress=print) -> Table:
    """Run the benchmark; returns the :class:`Table`."""
    cfg = QUICK if quick else FULL
    size = cfg["size"]
    table = Table(f"volumen bench pathtrace (CPU, {size[0]}x{size[1]}, studio rig; error vs {cfg['reference']} spp)",
                  [("case", "case", "s"), ("e_ref", "reference's own", ".4f"), ("e_raw16", "16 spp raw", ".4f"),
                   ("e_dn16", "16 spp denoised", ".4f"),
                   ("e_raw256", "256 spp raw", ".4f"),
                   ("bias", "bias (16 dn)", "+.4f"), ("spp_eq", "raw spp same time", "d"),
                   ("e_raw_eq", "raw same time", ".4f"), ("ratio", "dn / raw same time", ".3f"),
                   ("dn_s", "16 dn s", ".2f"), ("ok", "bars met", "s")])
    for name, (scene, cam) in _cases(quick).items():
        progress(f"[{name}]")
        table.add(case=name, **_compare(scene, cam, size, cfg["reference"], progress))
    sps = _speed(cfg["speed_shape"], cfg["speed_size"], progress)
    load = os.getloadavg()
    table.notes.append("error: mean |RGB difference| of linear premultiplied radiance over the pixels of alpha > 0.05;"
                       " bars (issue 24): 16 denoised <= 256 raw, denoised <= 1/3 of raw at the same time, |bias| <= "
                       "0.005")
    table.notes.append("reference's own: its estimated error, half the difference of its two independent halves "
                       "(each picture's error above includes it)")
    if sps is not None:
        w, h = cfg["speed_size"]
        table.notes.append(f"samples per pixel per second, aorta {'x'.join(map(str, cfg['speed_shape']))} at {w}x{h}"
                           f" (studio rig, ct-cinematic-vessels, anterior): {sps:.2f} (before issue 24: 0.83; bar "
                           f">= {4 * 0.83:.2f})")
    table.notes.append(f"load average during the run (1, 5, 15 min): {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} on "
                       f"{os.cpu_count()} CPUs")
    return table
