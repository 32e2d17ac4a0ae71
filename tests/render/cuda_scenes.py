"""Tiny scenes for comparing the ``cuda`` device with the CPU, and the script that renders them on the simulator.

``python cuda_scenes.py OUT.npz`` (with ``NUMBA_ENABLE_CUDASIM=1`` set before
numba loads, and ``NUMBA_DISABLE_JIT=1`` to run the shared functions as Python)
renders every scene of :func:`scenes` with ``device="cuda"``
and stores ``<name>/rgba``, ``<name>/depth``, ``<name>/value`` and a few
stats, plus the upload log of the caching checks (``uploads/*``). The
simulator runs each CUDA thread in Python, so pictures are 10x8 pixels and
volumes 16-20 voxels a side.
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace

import numpy as np

from volumen.core import (
    Camera,
    Clipping,
    ClipPlane,
    Isosurface,
    LabelLayer,
    LabelMap,
    Light,
    Sampling,
    Scene,
    Shading,
    TransferFunction,
    Volume,
)
from volumen.data import phantom

SIZE = (10, 8)
#: path-tracing samples per pixel of the "pathtrace" scene (fixed seed)
PT_SAMPLES = 3


def _setup():
    vol = phantom("head", size=(16, 20, 20))
    cam = Camera.orbit(vol, azimuth=-25, elevation=10, zoom=1.3)
    r, u, f = cam.basis()
    c = np.asarray(vol.center)
    pos = c + vol.diagonal * 1.3 * (0.6 * r + 0.6 * u - 0.5 * f)
    lights = (Light(position=tuple(pos), direction=tuple(c - pos), exponent=2.0, intensity=1.0, kind="spot"),
              Light(position=tuple(c - vol.diagonal * (0.9 * r + 0.3 * f)), color=(0.5, 0.7, 1.0), intensity=0.6),
              Light(position=tuple(c + vol.diagonal * (0.2 * r + 1.1 * u)), intensity=0.4, color=(1.0, 0.8, 0.6)))
    return vol, cam, lights


def _colour(vol: Volume) -> Volume:
    """A colour volume from ``vol``: red rising with the value, blue falling, green a band (uint8 RGB)."""
    lo, hi = vol.value_range()
    u = (vol.data - lo) / (hi - lo)
    rgb = np.stack([u, 4 * u * (1 - u), 1 - u], axis=-1)
    return Volume(np.rint(255 * rgb).astype(np.uint8), affine=vol.affine, spacing=vol.spacing)


def _labels(vol: Volume) -> LabelLayer:
    """Bone (above 400 HU) and a ball in the head, solid in their own colours over the scan's preset: the
    primary rays, the illumination volume's sweep and the shadow rays classify through them."""
    z, y, x = np.indices(vol.shape)
    lab = np.zeros(vol.shape, np.uint8)
    lab[(z - 8) ** 2 + (y - 10) ** 2 + (x - 11) ** 2 <= 16] = 2
    lab[vol.data > 400] = 1
    labels = LabelMap(lab, vol.spacing, vol.affine, {1: "bone", 2: "ball"}, {1: (0.95, 0.9, 0.8), 2: (0.9, 0.2, 0.2)})
    return LabelLayer(labels, opacity={"bone": 0.6, "ball": 0.5})


def scenes() -> dict:
    """name -> (Scene, Camera, size)."""
    vol, cam, lights = _setup()
    skin = TransferFunction.preset("ct-skin-bone")
    gray = TransferFunction.preset("mip-gray", value_range=vol.value_range())
    base = Scene(volume=vol, transfer=skin, lights=lights[:2], sampling=Sampling(seed=3))
    lv = dict(light_volume_scale=0.5)  # coarse lattices: the simulator runs one Python thread per lattice ray
    out = {
        "composite-none": base.with_(shading=Shading(mode="none")),
        "composite-headlight": base.with_(shading=Shading(mode="headlight")),
        "composite-phong": base.with_(shading=Shading(mode="phong")),
        "composite-preintegrated": base.with_(shading=Shading(mode="phong"),
                                              sampling=Sampling(preintegrate=True, samples_per_voxel=1.5, seed=3)),
        "mip": base.with_(mode="mip", transfer=gray, shading=Shading(mode="none")),
        "minip": base.with_(mode="minip", transfer=gray, shading=Shading(mode="none")),
        "average": base.with_(mode="average", transfer=gray, shading=Shading(mode="none")),
        "isosurface": base.with_(mode="isosurface", isosurface=Isosurface(value=300.0),
                                 shading=Shading(mode="headlight")),
        "shadows-fast": base.with_(shading=Shading(mode="shadows", **lv)),
        "shadows-direct": base.with_(shading=Shading(mode="shadows", shadow_method="direct")),
        "shadows-fast-clipped": base.with_(shading=Shading(mode="shadows", **lv), clipping=Clipping(
            crop=(0, 12, 0, 19, 0, 15), planes=(ClipPlane(point=tuple(vol.center), normal=(0.2, 0.1, -1)),))),
        "isosurface-shadows": base.with_(mode="isosurface", isosurface=Isosurface(value=300.0),
                                         shading=Shading(mode="shadows", **lv)),
        "scattering-fast": base.with_(lights=lights, shading=Shading(mode="scattering", phase_g=0.3, **lv)),
        "scattering-direct": base.with_(lights=lights, shading=Shading(mode="scattering", phase_g=-0.2,
                                                                       shadow_method="direct")),
        "pathtrace": base.with_(shading=Shading(mode="pathtrace", pt_samples=PT_SAMPLES, pt_bounces=3, phase_g=0.3,
                                                pt_denoise=False)),
        "colour-phong": base.with_(volume=_colour(vol), shading=Shading(mode="phong"), transfer=TransferFunction(
            color=((0, 1, 1, 1), (255, 1, 1, 1)), opacity=((0, 0), (40, 0), (255, 0.6)))),
        "labels-scattering-fast": base.with_(lights=lights[:1], labels=_labels(vol),
                                             shading=Shading(mode="scattering", phase_g=0.3, **lv)),
    }
    return {k: (v, cam, SIZE) for k, v in out.items()}


def upload_sequence():
    """(label, Scene, Camera): frames whose uploads the caching test checks, in order."""
    vol, cam, lights = _setup()
    s = Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"), lights=lights[:1],
              shading=Shading(mode="shadows", light_volume_scale=0.5))
    return [("first", s, cam), ("same", s, cam), ("camera", s, Camera.orbit(vol, azimuth=40)),
            ("transfer", s.with_(transfer=TransferFunction.preset("ct-skin-bone")), cam),
            ("light-intensity", s.with_(transfer=TransferFunction.preset("ct-skin-bone"),
                                        lights=(replace(lights[0], intensity=0.5),)), cam)]


def resized_sequence():
    """(label, Scene, Camera, size): one scene drawn at its size, a smaller one, then its own again (the device
    keeps its outputs while the size stays and makes new ones when it changes)."""
    scene, cam, size = scenes()["composite-phong"]
    return [("first", scene, cam, size), ("smaller", scene, cam, (7, 5)), ("again", scene, cam, size)]


def main(path: str) -> int:
    from volumen.render import render

    out = {}
    np.seterr(over="ignore")  # run as Python, the hashes of _sobol wrap modulo 2**64 as compiled code does
    for name, (scene, cam, size) in scenes().items():
        im = render(scene, cam, size, device="cuda")
        assert im.stats["backend"] == "cuda", im.stats
        out[f"{name}/rgba"] = im.rgba
        out[f"{name}/depth"] = im.depth
        if im.value is not None:
            out[f"{name}/value"] = im.value
        out[f"{name}/built"] = np.array(im.stats.get("light_volumes_built", 0))
        print(name, "ok", flush=True)
    log = []
    for label, scene, cam in upload_sequence():
        im = render(scene, cam, SIZE, device="cuda")
        log.append((label, im.stats["uploads"], im.stats["light_volumes_built"]))
    out["uploads"] = np.array(json.dumps(log))
    for label, scene, cam, size in resized_sequence():
        im = render(scene, cam, size, device="cuda")
        out[f"resized/{label}/rgba"] = im.rgba
        out[f"resized/{label}/depth"] = im.depth
    np.savez(path, **out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
