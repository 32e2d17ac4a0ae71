"""An anterior view is upright and not mirrored: the patient's right on the image's left, superior at the top."""

from __future__ import annotations

import numpy as np
import pytest

from volumen.core import Camera, Sampling, Scene, Shading, TransferFunction, Volume
from volumen.data import phantom
from volumen.render import default_mode, render, render_volume

SIZE = (64, 64)


def _marker_volume(flip_lps: bool = False) -> tuple[Volume, dict]:
    """A faint box with a dense bead on the patient's right (+x) and one at the top (+z), in world mm."""
    n = 40
    k, j, i = np.mgrid[:n, :n, :n].astype(np.float64)
    if flip_lps:  # voxel axes i -> Left, j -> Posterior, k -> Superior (DICOM order)
        affine = np.array([[-2.0, 0, 0, 39.0], [0, -2.0, 0, 39.0], [0, 0, 2.0, -39.0], [0, 0, 0, 1]])
    else:
        affine = np.array([[2.0, 0, 0, -39.0], [0, 2.0, 0, -39.0], [0, 0, 2.0, -39.0], [0, 0, 0, 1]])
    xyz = np.stack([i, j, k, np.ones_like(i)], -1) @ affine.T
    x, y, z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    marks = {"right_marker": (25.0, 0.0, 0.0), "vertex": (0.0, 0.0, 28.0)}
    d = np.zeros((n, n, n))
    for p in marks.values():
        d = np.maximum(d, 1000.0 * np.exp(-((x - p[0]) ** 2 + (y - p[1]) ** 2 + (z - p[2]) ** 2) / (2 * 3.0**2)))
    return Volume(d.astype(np.float32), spacing=(2.0, 2.0, 2.0), affine=affine), marks


def _mip(vol, cam, size=SIZE):
    scene = Scene(volume=vol, mode="mip", transfer=TransferFunction.preset("mip-gray", value_range=vol.value_range()),
                  sampling=Sampling(jitter=False))
    return render(scene, cam, size)


def _check_landmarks(cam, marks):
    (c_r, r_r), _ = cam.project(marks["right_marker"], SIZE)
    assert c_r < SIZE[0] / 2 - 4, "patient's right must be on the image's left"
    (_, r_v), _ = cam.project(marks["vertex"], SIZE)
    assert r_v < SIZE[1] / 2 - 4, "superior must be at the top (row 0)"
    return (int(c_r), int(r_r)), (int(SIZE[0] - 1 - c_r), int(r_r))


@pytest.mark.parametrize("flip_lps", [False, True])
def test_anterior_view_synthetic(flip_lps):
    vol, marks = _marker_volume(flip_lps)
    cam = Camera.anatomical(vol, "anterior", projection="orthographic")
    (c, r), (cm, rm) = _check_landmarks(cam, marks)
    im = _mip(vol, cam)
    assert im.value[r, c] > 800 and im.value[rm, cm] < 100  # the bead where projected, not mirrored
    (cv, rv), _ = cam.project(marks["vertex"], SIZE)
    assert im.value[int(rv), int(cv)] > 800 and im.value[SIZE[1] - 1 - int(rv), int(cv)] < 100


def test_lps_and_ras_storage_render_alike():
    # the same world object stored in two voxel orders renders to the same picture
    a, _ = _marker_volume(False)
    b, _ = _marker_volume(True)
    cam = Camera.anatomical(a, "anterior", projection="perspective")
    np.testing.assert_allclose(_mip(a, cam).value, _mip(b, cam).value, atol=1e-2)


def test_head_phantom_anterior_view(render_dir):
    size = (256, 256)  # pixels of ~1.5 mm: the 3 mm bead is resolved
    vol = phantom("head")
    lm = {k: np.asarray(v, float) for k, v in vol.meta["truth"]["landmarks"].items()}
    cam = Camera.anatomical(vol, "anterior", projection="perspective")
    (c_re, _), _ = cam.project(lm["right_eye"], size)
    (c_le, _), _ = cam.project(lm["left_eye"], size)
    assert c_re < size[0] / 2 < c_le
    (c, r), _ = cam.project(lm["right_marker"], size)
    c, r = int(c), int(r)
    cm, rm = size[0] - 1 - c, r
    assert c < size[0] / 2 - 16
    (_, r_eye), _ = cam.project(lm["right_eye"], size)
    (_, r_v), _ = cam.project(lm["vertex"], size)
    assert r_v < r_eye and r_v < size[1] / 2
    im = _mip(vol, cam, size)
    im.save(render_dir / "head_anterior_mip.png")
    # the dense bead (2000 HU) shows at its projection, and not at the mirrored place
    win = np.nanmax(im.value[r - 1:r + 2, c - 1:c + 2])
    mirror = np.nanmax(im.value[rm - 1:rm + 2, cm - 1:cm + 2])
    bead = float(vol.meta["truth"].get("marker_hu", 2000.0))
    assert win > 0.6 * bead and mirror < win - 500, (win, mirror)


def test_a_single_slice_is_drawn_face_on_as_the_slab_it_stands_for():
    """One axial slice (5 mm thick) opens face-on (from the feet, :func:`default_view`) and is drawn as its 5 mm
    slab: the same pictures as six copies of it 1 mm apart, built by hand (MIP exactly; composite within mean
    |diff| 1e-3, whose edge pixels differ by one step's entry). Drawn alone, the one sample spanned nothing: every
    pixel was empty, and the anterior view saw it edge-on. Patient's right on the image left, anterior on top."""
    j, i = np.mgrid[:40, :40].astype(float)
    x, y = i - 19.5, j - 19.5  # RAS mm
    plane = 100 + 900 * np.exp(-((x - 12) ** 2 + y ** 2) / 8) + 600 * np.exp(-(x ** 2 + (y - 12) ** 2) / 8)
    plane = np.round(plane).astype(np.int16)
    one = Volume(plane[None], affine=np.array([[1.0, 0, 0, -19.5], [0, 1, 0, -19.5], [0, 0, 5, 0], [0, 0, 0, 1]]))
    six = Volume(np.repeat(plane[None], 6, axis=0),
                 affine=np.array([[1.0, 0, 0, -19.5], [0, 1, 0, -19.5], [0, 0, 1, -2.5], [0, 0, 0, 1]]))
    cam = Camera.anatomical(six, "inferior", projection="orthographic")
    assert Camera.anatomical(one).position[2] < 0  # from the feet
    pictures = {}
    for mode, tf in (("mip", TransferFunction.preset("mip-gray", value_range=(0, 1000))),
                     ("composite", TransferFunction(opacity=((0, 0.0), (1000, 0.3))))):
        a, b = (render(Scene(volume=v, mode=mode, transfer=tf, sampling=Sampling(jitter=False)), cam, SIZE)
                for v in (one, six))
        diff = np.abs(a.rgba - b.rgba).mean()
        print(f"{mode}: largest alpha {a.rgba[..., 3].max():.3f}, mean |diff| from the stack {diff:.1e}")
        assert a.rgba[..., 3].max() > 0.5 and diff <= (0.0 if mode == "mip" else 1e-3)
        pictures[mode] = a
    value = pictures["mip"].value
    (cr, rr), _ = cam.project((12.0, 0.0, 0.0), SIZE)
    (ca, ra), _ = cam.project((0.0, 12.0, 0.0), SIZE)
    assert cr < SIZE[0] / 2 - 4 and ra < SIZE[1] / 2 - 4
    assert value[int(rr), int(cr)] > 900 and value[int(ra), int(ca)] > 650


def test_a_slab_is_drawn_as_its_mip_by_default():
    """With no mode named (``render_volume``, the command line, the browser viewer), a slab is drawn as its MIP:
    a single slice's is the image itself; a whole volume is composited."""
    one = Volume(np.arange(1600, dtype=np.int16).reshape(1, 40, 40), spacing=(5.0, 1.0, 1.0))
    assert default_mode(one) == "mip" and default_mode(phantom("head", size=(24, 24, 24))) == "composite"
    image = render_volume(one, size=SIZE, projection="orthographic")
    inside = np.isfinite(image.value)
    assert inside.mean() > 0.3 and np.nanmax(image.value) > 1500 and np.nanmin(image.value) < 100


def _slice_and_stack():
    """A 40 x 40 axial slice (5 mm) with a bright disc and a ring, and six copies of it 1 mm apart (its slab)."""
    j, i = np.mgrid[:40, :40].astype(float)
    r = np.hypot(i - 19.5, j - 19.5)
    plane = np.where(r < 8, 900, np.where(r < 14, 400, 0)).astype(np.int16)
    one = Volume(plane[None], affine=np.array([[1.0, 0, 0, -19.5], [0, 1, 0, -19.5], [0, 0, 5, 0], [0, 0, 0, 1]]))
    six = Volume(np.repeat(plane[None], 6, axis=0),
                 affine=np.array([[1.0, 0, 0, -19.5], [0, 1, 0, -19.5], [0, 0, 1, -2.5], [0, 0, 0, 1]]))
    return one, six, plane


def test_a_single_slice_keeps_its_labels_and_crop_on_its_slab():
    """Labels on the slice's grid and a crop box in its voxel indices follow it onto the slab: a label layer drew
    an error (the labels' grid (1, 40, 40) against the slab's (2, 40, 40)), and the crop z = 0 .. 0, the whole
    slice, cut the slab to its back face (an empty picture). Against the six-slice stack with its own labels and
    the crop z = 0 .. 5: within mean |diff| 1e-3 (the stack test's bound)."""
    from volumen.core import Clipping, LabelLayer, LabelMap

    one, six, plane = _slice_and_stack()
    cam = Camera.anatomical(six, "inferior", projection="orthographic")
    tf = TransferFunction(opacity=((0, 0.0), (1000, 0.3)))

    def drawn(v, z1):
        labels = LabelMap((v.data > 500).astype(np.uint8), v.spacing, v.affine, {1: "disc"}, {1: (1.0, 0.0, 0.0)})
        scene = Scene(volume=v, transfer=tf, sampling=Sampling(jitter=False), labels=LabelLayer(labels),
                      clipping=Clipping(crop=(0, 39, 0, 39, 0, z1)))
        return render(scene, cam, SIZE).rgba

    a, b = drawn(one, 0), drawn(six, 5)
    disc = a[SIZE[1] // 2, SIZE[0] // 2]
    print(f"mean |diff| {np.abs(a - b).mean():.1e}; the disc's pixel {disc.round(3)}")
    assert np.abs(a - b).mean() <= 1e-3 and disc[3] > 0.5 and disc[0] > 3 * disc[1]


def test_the_path_tracer_draws_a_single_slice():
    """The progressive path tracer (the app's CPU cinematic view) draws the slab too: it drew nothing."""
    from volumen.render import PathTracer

    one, _, _ = _slice_and_stack()
    scene = Scene(volume=one, transfer=TransferFunction(opacity=((0, 0.0), (1000, 0.3))))
    tracer = PathTracer(scene, Camera.anatomical(one, projection="orthographic"), (16, 16))
    tracer.step(2)
    assert tracer.coverage.max() > 0.3


def test_a_chunked_single_plane_is_drawn_as_its_slab(tmp_path):
    """A one-plane OME-Zarr (read lazily, drawn out of core brick by brick) is drawn as its slab too: the same
    pictures as the plane in memory (MIP, composite unshaded and lit by phong, within 1e-5, bricks of 16 cells),
    where it drew nothing. The slab is a lazy view (``ChunkedArray.repeat``): no chunk is read before the bricks
    are. Lit, the slab's edge normals lie at right angles to the view: before ``core.FACING`` their side, and
    so their light, was left to rounding, which differed between a brick and the whole (up to 0.35)."""
    import volumen

    one, _, _ = _slice_and_stack()
    volumen.save(one, tmp_path / "plane.ome.zarr", chunks=16)
    lazy = volumen.load(tmp_path / "plane.ome.zarr")
    assert lazy.shape == (1, 40, 40) and lazy.slab().shape == (2, 40, 40)
    assert lazy.data.stats["chunk_reads"] == 0
    cam = Camera.anatomical(one, projection="orthographic")
    composite = TransferFunction(opacity=((0, 0.0), (1000, 0.3)))
    for mode, tf, shading in (("mip", TransferFunction.preset("mip-gray", value_range=(0, 1000)), "none"),
                              ("composite", composite, "none"), ("composite", composite, "phong")):
        scene = Scene(volume=one, mode=mode, transfer=tf, sampling=Sampling(jitter=False),
                      shading=Shading(mode=shading))
        a, b = (render(scene.with_(volume=v), cam, SIZE, **kw) for v, kw in ((one, {}), (lazy, {"brick": 16})))
        print(f"{mode} {shading}: lit {(a.rgba[..., 3] > 0.05).mean():.2f} in memory, "
              f"{(b.rgba[..., 3] > 0.05).mean():.2f} out of core ({b.stats['bricks']} bricks)")
        assert b.stats["bricks"] > 1 and (b.rgba[..., 3] > 0.05).mean() > 0.2
        np.testing.assert_allclose(b.rgba, a.rgba, atol=1e-5)


@pytest.mark.parametrize("name", ["examples_rgb_color.dcm", "examples_jpeg2k.dcm", "examples_palette.dcm",
                                  "examples_ybr_color.dcm"])
def test_a_colour_slab_is_drawn_as_its_own_colours_by_default(name):
    """pydicom's colour ultrasound (one RGB / JPEG 2000 / palette frame, a 30-frame YBR cine) with no flags: the
    frame facing the viewer in its own colours (``default_preset`` opaque, ``default_shading`` none). Its mean
    colour in the picture is the frame's within 0.01 a channel (resampling); before, composited with
    ``mr-default`` under the headlight, 2-11 % of the picture was lit, at a mean of 0.02-0.05."""
    from pydicom.data import get_testdata_file

    import volumen
    from volumen.core import is_color_slab
    from volumen.render import default_shading, default_transfer

    vol = volumen.load(get_testdata_file(name))
    assert is_color_slab(vol) and default_shading(vol) == "none" and default_mode(vol) == "composite"
    # no mode named (the command line with --labels) is composite; an isosurface keeps the headlight
    assert default_transfer(vol, None).name == "mip-gray" and default_shading(vol, "isosurface") == "headlight"
    a = render_volume(vol, size=(160, 120)).rgba
    shown = a[..., 3] > 0.5
    mean = a[..., :3][shown].mean(axis=0)
    frames = [np.asarray(f, float).reshape(-1, 3).mean(axis=0) / 255 for f in (vol.data[0], vol.data[-1])]
    err = min(np.abs(mean - f).max() for f in frames)  # the frame facing the viewer: the first or the last
    print(f"{name}: {shown.mean():.0%} of the picture, mean colour {mean.round(3)}, off by {err:.4f}")
    assert shown.mean() > 0.2 and err < 0.01


def test_the_default_look_is_one_answer_for_every_kind_of_volume():
    """``render.default_look`` (what ``render_volume``, the command line, the app and ``volumen.show`` draw with no
    flags): a single CT slice as its MIP under a grey ramp, a colour frame opaque and unshaded, a CT volume in
    ``ct-skin-bone`` under the headlight; a transfer function named keeps every volume composited, a mode named is
    kept."""
    from pydicom.data import get_testdata_file

    import volumen
    from volumen.render import default_look

    one = volumen.load(get_testdata_file("CT_small.dcm"))
    frame = volumen.load(get_testdata_file("examples_rgb_color.dcm"))
    head = phantom("head", size=(24, 24, 24))
    looks = {k: default_look(v) for k, v in (("one", one), ("frame", frame), ("head", head))}
    assert [(m, tf.name, sh) for m, tf, sh in looks.values()] == [
        ("mip", "mip-gray", "headlight"), ("composite", "mip-gray", "none"), ("composite", "ct-skin-bone", "headlight")]
    assert default_look(one, transfer_named=True)[0] == "composite"
    assert default_look(frame, "isosurface")[2] == "headlight" and default_look(head, "mip")[1].name == "mip-gray"
