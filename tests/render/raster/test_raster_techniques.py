"""Every registered raster technique checked by a number; reduced viewports; shader files; light import."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from volumen.core import Camera, Isosurface, Sampling, Scene, Shading, TransferFunction
from volumen.render import render
from volumen.render.raster import TECHNIQUES, register_backends, render_reduced, upscale

TF = TransferFunction(color=((-1000, 0.9, 0.4, 0.2), (1000, 1.0, 1.0, 0.9)),
                      opacity=((-1000, 0.0), (-200, 0.0), (300, 0.04), (1000, 0.12)))
#: mean |rgba - ray caster| allowed per slicing variant (8-bit rounds every blend; pre-classification
#: interpolates classified voxels; the adaptive distributions place planes differently)
TOLERANCE = {"slicing-uint8": 0.02, "slicing-pre": 0.03, "slicing-float16": 0.005}


def _scene(volume, mode="composite"):
    return Scene(volume=volume, transfer=TF, mode=mode, shading=Shading(mode="none"),
                 isosurface=Isosurface(value=300.0),
                 sampling=Sampling(jitter=False, skip_empty=False, early_termination=1.0))


@pytest.mark.parametrize("name", sorted(TECHNIQUES))
def test_every_technique_agrees_with_the_ray_caster(gl, blob, name):
    """Walk the registry through ``volumen.render.render``: slicing variants reproduce the ray caster's
    composite picture (orthographic; mean |difference| < 2e-3, or the variant's stated tolerance),
    mesh variants its isosurface depth (median < 0.05 mm)."""
    backends = register_backends({})
    assert set(backends) == set(TECHNIQUES)
    tech = TECHNIQUES[name]
    cam = Camera.orbit(blob, azimuth=-20, elevation=30, projection="orthographic", zoom=1.15)
    if tech.kind == "slicing":
        scene = _scene(blob)
        ref = render(scene, cam, (48, 48))
        img = backends[name](scene, cam, (48, 48))
        mad = float(np.abs(ref.rgba - img.rgba).mean())
        assert ref.alpha.max() > 0.5 and mad < TOLERANCE.get(name, 2e-3), (name, mad)
        assert img.stats["planes"] > 40
    else:
        scene = _scene(blob, "isosurface")
        ref = render(scene, cam, (48, 48))
        img = backends[name](scene, cam, (48, 48))
        both = np.isfinite(ref.depth) & np.isfinite(img.depth)
        assert both.sum() > 200
        assert np.median(np.abs(ref.depth[both] - img.depth[both])) < 0.05
        assert img.stats["triangles"] > 1000


def test_register_backends_into_render():
    """The registry fills a backend table without creating a context; names keep their technique."""
    table = register_backends({"cpu": object()})
    assert "cpu" in table and all(table[n] is TECHNIQUES[n] for n in TECHNIQUES)


@pytest.mark.parametrize("backend", ["cpu", "slicing"])
def test_reduced_viewport_keeps_the_picture(gl, blob, backend):
    """Half-size rendering upscaled stays within 0.02 (mean) of the full-size picture, a quarter within
    0.04; fraction 1 returns the full render itself."""
    from volumen.render import BACKENDS

    register_backends(BACKENDS)
    scene = _scene(blob)
    cam = Camera.orbit(blob, azimuth=30, elevation=10, zoom=1.2)
    full = render(scene, cam, (64, 64), backend=backend)
    half = render_reduced(scene, cam, (64, 64), 0.5, backend=backend)
    quarter = render_reduced(scene, cam, (64, 64), 0.25, backend=backend)
    same = render_reduced(scene, cam, (64, 64), 1.0, backend=backend)
    assert half.rgba.shape == full.rgba.shape and half.stats["reduced"]["render_size"] == (32, 32)
    e2, e4 = (float(np.abs(full.rgba - x.rgba).mean()) for x in (half, quarter))
    assert e2 < 0.02 and e4 < 0.04 and e2 < e4, (e2, e4)
    assert np.array_equal(same.rgba, full.rgba)


def test_upscale_keeps_the_frustum():
    """A linear ramp across the picture stays the same ramp after upscaling (geometry of pixel centres)."""
    from volumen.core import Image

    w, h = 20, 10
    x = (np.arange(w) + 0.5 - w / 2) / (h / 2)  # screen coordinate of each column centre
    small = Image(rgba=np.broadcast_to(np.stack([x, x, x, np.ones(w)], -1)[None], (h, w, 4)).copy(),
                  depth=np.zeros((h, w)))
    big = upscale(small, (40, 20))
    xb = (np.arange(40) + 0.5 - 20) / 10
    inside = np.abs(xb) < x.max()
    assert np.allclose(big.rgba[5, inside, 0], xb[inside], atol=1e-5)


def test_shader_files_ship_and_import_stays_light():
    """The .glsl files are package data read through importlib.resources; importing the raster package
    loads neither moderngl nor numba."""
    from volumen.render.raster._shaders import SHADER_FILES, shader_source

    for name in SHADER_FILES:
        assert len(shader_source(name)) > 500
    code = "import sys, volumen.render.raster; print([m for m in ('moderngl', 'numba') if m in sys.modules])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "[]"
