"""Every OpenGL technique and option value checked by a number; reduced viewports; shader files; light import."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from volumen.core import Camera, Isosurface, Sampling, Scene, Shading, TransferFunction
from volumen.render import TECHNIQUES, option_choices, render, render_reduced, upscale

TF = TransferFunction(color=((-1000, 0.9, 0.4, 0.2), (1000, 1.0, 1.0, 0.9)),
                      opacity=((-1000, 0.0), (-200, 0.0), (300, 0.04), (1000, 0.12)))
#: mean |rgba - ray caster| allowed per slicing option value (8-bit rounds every blend; pre-classification
#: interpolates classified voxels; the adaptive distributions place planes differently)
TOLERANCE = {"uint8": 0.02, "pre": 0.03, "float16": 0.005}


def _variants() -> list[tuple[str, dict]]:
    """Every technique drawn by OpenGL with its default options, then with each other value of each choice
    option (one changed at a time), read from the registry."""
    out = []
    for name, spec in TECHNIQUES.items():
        if spec.devices != ("gl",):
            continue
        out.append((name, {}))
        defaults = spec.options()
        for field, choices in option_choices(name).items():
            if isinstance(choices, tuple):
                out += [(name, {field: c}) for c in choices if c != getattr(defaults, field)]
    return out


def _scene(volume, mode="composite"):
    return Scene(volume=volume, transfer=TF, mode=mode, shading=Shading(mode="none"),
                 isosurface=Isosurface(value=300.0),
                 sampling=Sampling(jitter=False, skip_empty=False, early_termination=1.0))


@pytest.mark.parametrize(("name", "options"), _variants(), ids=lambda v: v if isinstance(v, str) else
                         "-".join(map(str, v.values())) or "default")
def test_every_technique_agrees_with_the_ray_caster(gl, blob, name, options):
    """Walk the registry through ``volumen.render.render``: slicing variants reproduce the ray caster's
    composite picture (orthographic; mean |difference| < 2e-3, or the option value's stated tolerance),
    mesh variants its isosurface depth (median < 0.05 mm)."""
    cam = Camera.orbit(blob, azimuth=-20, elevation=30, projection="orthographic", zoom=1.15)
    if name == "slicing":
        scene = _scene(blob)
        ref = render(scene, cam, (48, 48))
        img = render(scene, cam, (48, 48), technique=name, **options)
        mad = float(np.abs(ref.rgba - img.rgba).mean())
        tol = max([TOLERANCE.get(v, 2e-3) for v in options.values()] + [2e-3])
        assert ref.alpha.max() > 0.5 and mad < tol, (name, options, mad)
        assert img.stats["planes"] > 40
    else:
        scene = _scene(blob, "isosurface")
        ref = render(scene, cam, (48, 48))
        img = render(scene, cam, (48, 48), technique=name, **options)
        both = np.isfinite(ref.depth) & np.isfinite(img.depth)
        assert both.sum() > 200
        assert np.median(np.abs(ref.depth[both] - img.depth[both])) < 0.05
        assert img.stats["triangles"] > 1000
    assert img.stats["renderer"] == {"device": "gl", "technique": name}
    assert img.stats["options"] == {**TECHNIQUES[name].options().to_dict(), **options}


def test_the_variants_of_volumen_0_1_are_the_same_pictures(gl, blob):
    """Each backend name of volumen 0.1 (``slicing-uint8``...) still draws, warning, the picture of its device
    and technique (bit for bit)."""
    from volumen.render import legacy_backend
    from volumen.render._techniques import _LEGACY

    scene, cam = _scene(blob), Camera.orbit(blob, azimuth=-20, elevation=30, projection="orthographic")
    for old in ("slicing-uint8", "slicing-near-quarter", "mesh-gouraud"):
        device, tech = legacy_backend(old)
        with pytest.warns(DeprecationWarning, match="device= and technique="):
            a = render(scene, cam, (24, 24), backend=old)
        b = render(scene, cam, (24, 24), device=device, technique=tech)
        np.testing.assert_array_equal(a.rgba, b.rgba)
    assert len(_LEGACY) == 14


@pytest.mark.parametrize("technique", ["raycast", "slicing"])
def test_reduced_viewport_keeps_the_picture(gl, blob, technique):
    """Half-size rendering upscaled stays within 0.02 (mean) of the full-size picture, a quarter within
    0.04; fraction 1 returns the full render itself."""
    scene = _scene(blob)
    cam = Camera.orbit(blob, azimuth=30, elevation=10, zoom=1.2)
    full = render(scene, cam, (64, 64), technique=technique)
    half = render_reduced(scene, cam, (64, 64), 0.5, technique=technique)
    quarter = render_reduced(scene, cam, (64, 64), 0.25, technique=technique)
    same = render_reduced(scene, cam, (64, 64), 1.0, technique=technique)
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


def test_shader_files_are_found_in_their_folder(tmp_path):
    """The shader list is the ``.glsl`` files of the package's folder (by ``pathlib``, a second way of listing it),
    and a ``.glsl`` file added to a folder is picked up with no list to edit; other files are not."""
    import volumen.render.raster
    from volumen.render.raster._shaders import SHADER_FILES, glsl_files

    folder = Path(volumen.render.raster.__file__).parent / "shaders"
    assert SHADER_FILES == tuple(sorted(p.stem for p in folder.glob("*.glsl")))
    assert {"raycast", "raycast_modes", "display", "preamble", "lighting"} <= set(SHADER_FILES)
    for name in ("b", "a"):
        (tmp_path / f"{name}.glsl").write_text("void main() {}\n")
    (tmp_path / "notes.txt").write_text("not a shader\n")
    assert glsl_files(tmp_path) == ("a", "b")
    (tmp_path / "added.glsl").write_text("void main() {}\n")
    assert glsl_files(tmp_path) == ("a", "added", "b")


@pytest.mark.parametrize("tonemap", ["aces", "linear"])
def test_display_shader_equals_image_to_uint8(gl, tonemap):
    """display.glsl, the browser viewer's display pass, compiled from the same file as desktop GLSL 3.30 with the
    constants of core._tonemap.shader_constants(): a picture of premultiplied linear RGBA (radiance 0..8, every
    alpha, empty and opaque pixels) shown at a given exposure equals ``Image.to_uint8`` over black of that
    Display to 1/255 (8-bit rounding of float32 against float64 arithmetic)."""
    from volumen.core import Display, Image
    from volumen.core._tonemap import shader_constants
    from volumen.render.raster import on_gl_thread
    from volumen.render.raster._context import Target
    from volumen.render.raster._shaders import program

    n, ev = 32, 0.7
    rng = np.random.default_rng(7)
    a = rng.uniform(0.0, 1.0, (n, n, 1))
    a[0, :4], a[1, :4] = 0.0, 1.0
    rgba = np.concatenate([8.0 * rng.uniform(0.0, 1.0, (n, n, 3)) ** 3 * a, a], axis=-1).astype(np.float32)
    k = shader_constants()

    def draw():
        prog = program(gl, "display")
        tex = gl.texture((n, n), 4, rgba.tobytes(), dtype="f4")
        vbo = gl.buffer(np.array([-1, -1, 3, -1, -1, 3], np.float32).tobytes())
        vao = gl.vertex_array(prog, [(vbo, "2f", "in_pos")])
        prog["u_linear"].value = 0
        prog["u_viewport"].value = (0.0, 0.0, float(n), float(n))
        prog["u_tonemap"].value = {"linear": 0, "aces": 1}[tonemap]
        prog["u_gain"].value = 2.0 ** ev
        prog["u_aces"].value = tuple(k["aces"])
        prog["u_srgb"].value = tuple(k["srgb"])
        with Target(gl, (n, n), [(4, "f4")]) as t:
            t.use()
            tex.use(0)
            vao.render()
            out = t.read()
        for obj in (vao, vbo, tex):
            obj.release()
        return out[::-1]   # read() puts row 0 at the top; the texture's row 0 is at the bottom

    got = np.rint(np.clip(on_gl_thread(draw)[..., :3], 0.0, 1.0) * 255).astype(int)
    image = Image(rgba, np.zeros((n, n), np.float32))
    ref = image.to_uint8(display=Display(tonemap=tonemap, exposure=ev)).astype(int)
    assert np.abs(got - ref).max() <= 1 and np.mean(got != ref) < 0.02, np.abs(got - ref).max()
