"""What the server sends, checked without a browser: the volume fitted to a texture size and budget and
encoded as 16 bits (exactly where it can be), the frames' binary layout, the scenes the viewer refuses, the
slice pictures and their pixel -> world map, and the shader sources of both dialects."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Scene, Shading, TransferFunction, Volume, Window, canonical, slice_image
from volumen.data import phantom
from volumen.errors import DeviceLimitError
from volumen.web import ServedVolume, decode, encode, web_frame
from volumen.web._served import encode_half, fit_volume


def test_integer_ct_is_sent_exactly_and_floats_within_half_a_table_entry():
    """int16 data spanning <= 4097 values: the half-float texels plus the map give the table units of every
    voxel exactly; float data (and wider integer ranges): within 0.5 table units (1/8190 of the range)."""
    rng = np.random.default_rng(1)
    u = rng.integers(-1024, 3072, size=(6, 7, 8)).astype(np.int16)
    u0, ufac = -1024.0, 4095.0 / 4095.0
    texels, (add, mul), exact = encode_half(u, u0, ufac)
    assert exact and texels.dtype == np.float16
    assert np.array_equal((texels.astype(np.float64) + add) * mul, (u - u0) * ufac)
    f = rng.uniform(0, 4095, size=(6, 7, 8)).astype(np.float32)
    texels, (add, mul), exact = encode_half(f, 0.0, 1.0)
    assert not exact
    assert np.abs((texels.astype(np.float64) + add) * mul - f).max() <= 0.5
    wide = rng.integers(0, 60000, size=(4, 4, 4)).astype(np.int32)
    texels, (add, mul), exact = encode_half(wide, 0.0, 4095 / 60000)
    assert not exact and np.abs((texels.astype(np.float64) + add) * mul - wide * 4095 / 60000).max() <= 0.5


def test_a_large_volume_is_resampled_to_the_budget_and_the_texture_size():
    """A volume past the budget (2 bytes a voxel) or an axis past the client's 3-D texture size is resampled
    onto a coarser grid covering the same box (within one new voxel), with a notice; a fitting one is kept."""
    vol = phantom("head", size=(36, 40, 40))
    fitted, factor = fit_volume(vol, 2048, 2 * 40 ** 3)
    assert fitted is vol and factor == 1.0
    served = ServedVolume(vol, max_3d=2048, budget_mb=2 * 20 ** 3 / 2 ** 20)
    v = served.volume
    assert 2 * np.prod(v.shape) <= 2 * 20 ** 3 and served.factor > 1 and "resampled" in served.notices[0]
    lo, hi = vol.bounds()
    lo2, hi2 = v.bounds()
    assert np.allclose(lo2, lo) and np.all(hi2 <= hi + 1e-6) and np.all(hi - hi2 < np.array(v.spacing[::-1]))
    small = ServedVolume(vol, max_3d=24, budget_mb=256).volume
    assert max(small.shape) <= 24
    info = served.info()
    assert info["shape"] == list(v.shape) and "name" not in info and "meta" not in info


def test_frames_round_trip_and_refuse_what_the_viewer_does_not_draw():
    vol = phantom("head", size=(24, 24, 24))
    scene = Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"), shading=Shading(mode="headlight"))
    cam = Camera.orbit(vol)
    header, arrays = web_frame(vol, scene.to_dict(), cam.to_dict(), (32, 24))
    h2, a2 = decode(encode(header, arrays))
    assert h2["defines"] == {"MODE": 0, "LIGHT": 1, "MAX_LIGHTS": 16, "MAX_PLANES": 16, "FACING": "1e-06"}
    assert h2["uniforms"]["u_wh"] == [32.0, 24.0] and len(h2["uniforms"]["u_to_index"]) == 16
    for name, a in arrays.items():
        assert a2[name].dtype == a.dtype and np.array_equal(a2[name], a), name
    with pytest.raises(DeviceLimitError, match="path tracing"):
        web_frame(vol, scene.with_(shading=Shading(mode="pathtrace")).to_dict(), cam.to_dict(), (8, 8))
    with pytest.raises(ValueError, match="Scene.mode"):
        web_frame(vol, {**scene.to_dict(), "mode": "x-ray"}, cam.to_dict(), (8, 8))
    with pytest.raises(ValueError, match="picture size"):
        web_frame(vol, scene.to_dict(), cam.to_dict(), (0, 8))


def test_slice_pictures_are_the_core_slices_and_map_pixels_to_world():
    """The server's slice PNG is ``core.slice_image`` of the plane through the crosshair; its pixel map sends
    the pixel where the other planes cross (which it reports with their names) to the crosshair's world point
    (to within a voxel: the slice is the nearest voxel's)."""
    from io import BytesIO

    from PIL import Image as PILImage

    from volumen.web._slices import slice_png

    vol = Volume(phantom("head", size=(30, 40, 36)).data, spacing=(2.0, 1.0, 1.5), modality="CT", units="HU")
    point = np.asarray(vol.center) + [5.0, -4.0, 6.0]
    can = canonical(vol)
    others = {"axial": ("coronal", "sagittal"), "coronal": ("axial", "sagittal"), "sagittal": ("axial", "coronal")}
    for plane in ("axial", "coronal", "sagittal"):
        png, m, cross = slice_png(vol, plane, point, 40.0, 400.0)
        gray = np.asarray(PILImage.open(BytesIO(png)))
        expected = slice_image(can, plane, world=point, window=Window(40.0, 400.0), canonical_volume=can)
        assert np.array_equal(gray, expected), plane
        assert (cross["row_plane"], cross["col_plane"]) == others[plane]
        world = m[0] + cross["col"] * m[1] + cross["row"] * m[2]
        assert np.all(np.abs(world - point) <= max(vol.spacing) / 2 + 1e-6), (plane, world, point)


def test_both_dialects_come_from_the_same_files():
    """raycast.glsl carries no #version line; GLSL 3.30 and GLSL ES 3.00 stages differ only in the first line
    (the preamble's precision statements are under GL_ES, which only ES compilers define)."""
    from volumen.render.raster._shaders import shader_source, stage_source

    assert not shader_source("raycast").startswith("#version")
    d = {"MODE": 0, "LIGHT": 2, "MAX_LIGHTS": 16, "MAX_PLANES": 16}
    desktop, es = (stage_source("raycast", "fragment", d, dialect) for dialect in ("gl330", "es300"))
    assert desktop.split("\n", 1)[0] == "#version 330 core" and es.split("\n", 1)[0] == "#version 300 es"
    assert desktop.split("\n", 1)[1] == es.split("\n", 1)[1]
    assert "precision highp sampler3D;" in es and "#if defined GL_ES" in es


def test_a_single_slice_is_served_as_its_slab():
    """The page draws a single slice as the slab it stands for (``Volume.slab``), not a box of no thickness."""
    one = Volume(np.arange(400, dtype=np.int16).reshape(1, 20, 20), spacing=(5.0, 0.7, 0.7))
    served = ServedVolume(one)
    assert served.volume.shape == (2, 20, 20) and np.isclose(served.volume.extent[2], 5.0)
    assert served.info()["source_shape"] == [1, 20, 20]


def test_a_single_slice_fitted_to_the_texture_keeps_its_slab():
    """A slice too large for the client's 3-D texture is coarsened in plane only: its slab keeps two samples (the
    thickness), where a coarser grid along it left one (a box of no thickness, an empty 3-D view)."""
    one = Volume(np.arange(90 * 60, dtype=np.int16).reshape(1, 90, 60), spacing=(5.0, 0.7, 0.7))
    served = ServedVolume(one, max_3d=32)
    assert served.factor > 2 and served.volume.shape[0] == 2 and max(served.volume.shape) <= 32
    assert np.isclose(served.volume.extent[2], 5.0) and np.allclose(served.volume.extent[:2], one.extent[:2], rtol=0.05)


def test_a_chunked_volume_is_served_read_from_the_finest_level_that_fits(tmp_path):
    """``volumen serve scan.ome.zarr`` answered the page's volume request with a 500 (the kernels that encode the
    texels got the lazy chunked array). The page now gets it read into memory: the whole level 0 where it fits,
    else the finest pyramid level that fits the client's texture; a one-plane OME-Zarr as its slab."""
    import volumen

    v = Volume((np.arange(40 * 36 * 30) % 997).astype(np.int16).reshape(40, 36, 30), spacing=(1.0, 1.0, 1.0))
    volumen.save(v, tmp_path / "v.ome.zarr", chunks=8)
    lazy = volumen.load(tmp_path / "v.ome.zarr")
    whole = ServedVolume(lazy)
    assert whole.factor == 1.0 and np.array_equal(whole.volume.data, v.data)
    assert whole.encoded[0].shape == v.shape  # the texels the page draws
    small = ServedVolume(lazy, max_3d=24)
    assert small.volume.meta["level"] == 1 and small.volume.shape == (20, 18, 15) and small.factor == 1.0
    volumen.save(v.crop(z=slice(7, 8)), tmp_path / "plane.ome.zarr", chunks=8)
    plane = ServedVolume(volumen.load(tmp_path / "plane.ome.zarr"))
    assert plane.volume.shape == (2, 36, 30) and np.array_equal(plane.volume.data[1], v.data[7])


def test_the_page_is_told_the_slices_first_window_as_the_app_opens_with():
    """The page's slice views start at ``core.default_window`` (the server's, not a rule of the page's own): soft
    tissue for a CT, the display range for an MRI with outliers (``core.display_range``), as the app."""
    from volumen.core import default_window

    for vol in (phantom("head", size=24), phantom("mr_head", size=32)):
        w = default_window(vol)
        assert ServedVolume(vol).info()["window"] == {"level": w.level, "width": w.width}
    assert ServedVolume(phantom("head", size=24)).info()["window"] == {"level": 40.0, "width": 400.0}


def test_the_pages_sliders_and_histogram_span_the_table_range_not_a_fill():
    """``value_range`` (the page's iso, shift and window sliders) and the histogram span ``core.table_range``: for
    an MRI filled with -1e6 outside its field of view, 1.2..2,826, not -1e6..2,826, where the sliders' 500 steps
    were 2,000 units each (three times the tissue's range) and every voxel of tissue fell in the histogram's last
    bin. A volume without a fill keeps its data range."""
    from volumen.core import table_range
    from volumen.data import fill_outside_field

    mr = phantom("mr_head", size=32, dtype="float32")
    for vol in (fill_outside_field(mr, -1e6), mr):
        served = ServedVolume(vol)
        info = served.info()
        lo, hi = table_range(served.volume)
        assert info["value_range"] == [lo, hi] and info["histogram"]["edges"][0] == pytest.approx(lo, rel=1e-6)
    assert info["value_range"] == list(served.volume.value_range())
    filled = ServedVolume(fill_outside_field(mr, -1e6)).info()
    tissue = np.asarray(filled["histogram"]["counts"])[np.asarray(filled["histogram"]["edges"][:-1]) >= 0]
    assert np.count_nonzero(tissue) >= 5 and filled["value_range"][1] - filled["value_range"][0] < 20000


_FIRST_REQUESTS = r"""
import http.client, sys, threading
from tests.web.web_helpers import reference_scenes, start_server

vol = reference_scenes.volumes()["head"][0]
scene, cam, _ = reference_scenes.scenes()["head/composite/headlight"]
srv = start_server(vol, scene, cam)
paths = ["/info.json", "/shaders.json", "/volume.bin", "/info.json?max3d=64",
         "/slice.png?plane=axial&x=0&y=0&z=0&level=40&width=400"]
status = {}

def ask(path):
    c = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=120)
    c.request("GET", path, headers={"X-Volumen-Token": srv.token})
    r = c.getresponse()
    r.read()
    status[path] = r.status

before = set(sys.modules)
threads = [threading.Thread(target=ask, args=(p,)) for p in paths]
for t in threads:
    t.start()
for t in threads:
    t.join()
srv.stop()
late = sorted(m for m in set(sys.modules) - before if m.startswith("volumen"))
print(sorted(status.items()), late)
sys.exit(any(s != 200 for s in status.values()) or bool(late))
"""


def test_a_fresh_servers_first_requests_at_once_are_all_answered():
    """In a new process, the first requests to the routes at once (each in its own thread) are all answered 200 and
    import no volumen module: the routes' modules are imported with the server, so two request threads never
    import one at once (Python's import locks answered that with a _DeadlockError, a 500)."""
    import subprocess
    import sys

    from tests.web.web_helpers import ROOT

    r = subprocess.run([sys.executable, "-c", _FIRST_REQUESTS], cwd=ROOT, capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr[-2000:]
