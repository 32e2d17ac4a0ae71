"""Pictures as 8-bit PNG content before the display transform: ``--tonemap linear`` must give them
back bit for bit.

``python linear_scenes.py OUT.npz`` renders every scene of :func:`scenes` on the CPU (:func:`render_linear`) and
stores each picture's ``Image.to_uint8`` over two backgrounds (black, and a grey with ``encoding="srgb"``) as
uint8 arrays. ``linear_pictures.npz`` beside this file was written by the code of commit acb0293, before the
display transform, the environment light and the studio rig existed (``test_display.py`` compares), and
re-written once since, when the normals' direction table was packed into 10-bit components: of the
6912 bytes of each picture that reads normals (headlight; Phong, shadows and isosurface with a light), 13-41
moved, by 1 (5 in a specular highlight of ``composite/phong/light``); the others kept every byte. The path tracer is
left out: its estimator changed in the same issue (another sampler, the majorant grid), so its noise differs by
design; ``test_pathtrace.py`` checks that it converges to the same pictures.
"""

from __future__ import annotations

import sys

import numpy as np

from volumen.core import Camera, Isosurface, Light, Sampling, Scene, Shading, TransferFunction
from volumen.data import phantom

SIZE = (48, 48)
SHADINGS = ("none", "headlight", "phong", "shadows", "scattering")
BACKGROUNDS = {"black": ((0.0, 0.0, 0.0), "linear"), "grey-srgb": ((0.3, 0.4, 0.5), "srgb")}


def scenes() -> dict:
    """name -> (Scene, Camera, size): every shading with and without lights, and the projections."""
    vol = phantom("head", size=(40, 48, 48))
    cam = Camera.orbit(vol, azimuth=-30, elevation=15, zoom=1.2)
    r, u, f = cam.basis()
    c, d = np.asarray(vol.center), vol.diagonal
    lights = (Light(position=tuple(c + d * (0.8 * r + 0.7 * u - 0.6 * f)), intensity=1.4, color=(1.0, 0.9, 0.8)),)
    base = Scene(volume=vol, transfer=TransferFunction.preset("ct-skin-bone"),
                 sampling=Sampling(seed=3, adaptive=False))  # the full-rate pictures of before
    out = {}
    for sh in SHADINGS:
        out[f"composite/{sh}"] = (base.with_(shading=Shading(mode=sh)), cam, SIZE)
        out[f"composite/{sh}/light"] = (base.with_(shading=Shading(mode=sh), lights=lights), cam, SIZE)
    out["isosurface/phong/light"] = (base.with_(mode="isosurface", isosurface=Isosurface(value=300.0),
                                                shading=Shading(mode="phong"), lights=lights), cam, SIZE)
    gray = TransferFunction.preset("mip-gray", value_range=vol.value_range())
    out["mip"] = (base.with_(mode="mip", transfer=gray, shading=Shading(mode="none")), cam, SIZE)
    return out


def pictures(render, scenes_) -> dict:
    """name/background -> uint8 picture."""
    out = {}
    for name, (scene, cam, size) in scenes_.items():
        im = render(scene, cam, size)
        for bname, (bg, enc) in BACKGROUNDS.items():
            out[f"{name}/{bname}"] = im.to_uint8(bg, encoding=enc)
    return out


def render_linear(scene, cam, size):
    """The picture with ``tonemap="linear"`` and the uniform environment: the pictures of before the display
    transform."""
    from volumen.core import Display, Environment
    from volumen.render import render

    return render(scene.with_(display=Display(tonemap="linear"), environment=Environment(kind="uniform")), cam, size)


if __name__ == "__main__":
    np.savez_compressed(sys.argv[1], **pictures(render_linear, scenes()))
