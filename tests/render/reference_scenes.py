"""Reference pictures of the ray caster: every mode x every shading on two phantoms and a real CTA.

``python reference_scenes.py OUT.npz`` renders every scene of :func:`scenes`
with the CPU backend and stores each picture's rgba as uint16
(``round(rgba * 65535)``, quantization error <= 7.7e-6) in a compressed
``.npz``. ``reference_pictures.npz`` beside this file was written by the
renderer before its rewrite, the ``composite/pathtrace`` pictures again by the path tracer
(another sampler and majorant grid: other noise; ``test_pathtrace.py`` holds it to the scattering model),
and again when its samples began to cover the pixel's area (a box filter, not the pixel's centre);
``test_reference.py`` checks that the
current renderer still draws the same pictures (mean |RGBA diff| <= 0.002).

Shading applies to composite and isosurface only (the projections ignore it),
so mip / minip / average are drawn once each. Pictures are 96x96 (the
path-traced ones with 4 samples per pixel, fixed seed) so the file stays small.
"""

from __future__ import annotations

import sys
from functools import cache

import numpy as np

from volumen.core import Camera, Display, Isosurface, Light, Sampling, Scene, Shading, TransferFunction
from volumen.data import phantom, shared_data

SIZE = (96, 96)
#: the VMTK aorta, or None where the shared data folder is missing
AORTA = shared_data("vmtk-aorta", "aorta.mha")
#: shading name -> Shading (the two lit-model variants of shadows: fast and direct)
SHADINGS = {
    "none": Shading(mode="none"),
    "headlight": Shading(mode="headlight"),
    "phong": Shading(mode="phong"),
    "shadows-fast": Shading(mode="shadows", light_volume_scale=1.0),
    "shadows-direct": Shading(mode="shadows", shadow_method="direct"),
    "scattering": Shading(mode="scattering", phase_g=0.3, light_volume_scale=1.0),
    "pathtrace": Shading(mode="pathtrace", pt_samples=4, pt_bounces=2, pt_denoise=False),
}
PROJECTIONS = ("mip", "minip", "average")


def _aorta():
    """VMTK's aorta (float32 on disk, HU + 1000 with fractions) rounded to int16, as CT is stored: the pictures
    then run the ray caster's int16 kernels, which the phantoms' scenes compile anyway (float32 twins of every
    mode and shading only for this scan were 200 s of the suite's cold compilation); the float32 path is
    checked by ``test_integer_data_sampled_directly_draws_the_same`` (int16 in place vs a float32 copy)."""
    import numpy as np

    from volumen.io import load

    vol = load(AORTA)
    return vol.with_data(np.rint(vol.data).astype(np.int16))


@cache
def volumes() -> dict:
    """name -> (Volume, composite TransferFunction, isosurface value, camera zoom); the aorta where its file exists."""
    out = {"head": (phantom("head", size=(40, 48, 48)), TransferFunction.preset("ct-skin-bone"), 300.0, 1.2),
           "torso": (phantom("torso", size=(40, 48, 48)), TransferFunction.preset("ct-bone"), 200.0, 1.2)}
    if AORTA is not None:  # scanner units: the CT presets shifted by +1000, contrast lumen ~1600-2200
        out["aorta"] = (_aorta(), TransferFunction.preset("ct-vessels").shifted(1000.0), 1400.0, 2.0)
    return out


def _lights(vol, cam) -> tuple:
    r, u, f = cam.basis()
    c = np.asarray(vol.center)
    d = vol.diagonal
    return (Light(position=tuple(c + d * (0.8 * r + 0.7 * u - 0.6 * f)), intensity=0.9, color=(1.0, 0.9, 0.8)),
            Light(position=tuple(c + d * (-0.9 * r + 0.4 * u - 0.5 * f)), direction=tuple(0.9 * r - 0.4 * u + 0.5 * f),
                  exponent=2.0, intensity=0.6, color=(0.6, 0.8, 1.0)))


def scenes() -> dict:
    """name -> (Scene, Camera, size)."""
    out = {}
    for vname, (vol, tf, iso, zoom) in volumes().items():
        cam = Camera.orbit(vol, azimuth=-30, elevation=15, zoom=zoom)
        base = Scene(volume=vol, transfer=tf, lights=_lights(vol, cam), sampling=Sampling(seed=7),
                     display=Display(tonemap="linear"))  # the pictures as rendered before the display transform
        gray = TransferFunction.preset("mip-gray", value_range=vol.value_range())
        for p in PROJECTIONS:
            out[f"{vname}/{p}"] = (base.with_(mode=p, transfer=gray, shading=Shading(mode="none")), cam, SIZE)
        for sname, sh in SHADINGS.items():
            out[f"{vname}/composite/{sname}"] = (base.with_(shading=sh), cam, SIZE)
            iso_scene = base.with_(mode="isosurface", isosurface=Isosurface(value=iso), shading=sh)
            out[f"{vname}/isosurface/{sname}"] = (iso_scene, cam, SIZE)
    return out


def quantize(rgba) -> np.ndarray:
    return np.round(np.clip(np.asarray(rgba, np.float64), 0, 1) * 65535).astype(np.uint16)


def main(path: str) -> None:
    from volumen.render import render

    pics = {}
    for name, (scene, cam, size) in scenes().items():
        pics[name] = quantize(render(scene, cam, size).rgba)
        print(name, f"{pics[name][..., 3].mean() / 65535:.3f}", flush=True)
    np.savez_compressed(path, **pics)


if __name__ == "__main__":
    main(sys.argv[1])
