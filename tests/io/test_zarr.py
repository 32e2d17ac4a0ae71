"""OME-Zarr: lazy reading of v2 and v3 pyramids, geometry round trip, slices reading only their chunks."""

import numpy as np
import pytest

import volumen
from volumen.core import Volume, canonical, slice_at
from volumen.errors import CorruptDataError

zarr = pytest.importorskip("zarr", reason="the scale extra (zarr) is not installed")


def _volume():
    rng = np.random.default_rng(3)
    data = rng.integers(-1000, 2000, size=(40, 36, 30)).astype(np.int16)
    aff = np.array([[-0.8, 0, 0, 12.0], [0, 0.0, 1.5, -7.0], [0, 1.2, 0, 3.0], [0, 0, 0, 1]])  # flipped, permuted
    return Volume(data, spacing=(1.5, 1.2, 0.8), affine=aff, modality="CT", units="HU", name="t")


@pytest.mark.parametrize("fmt", [2, 3])
def test_round_trip_and_pyramid(tmp_path, fmt):
    v = _volume()
    p = tmp_path / "t.ome.zarr"
    volumen.save(v, p, chunks=16, zarr_format=fmt)
    w = volumen.load(p)
    assert w.data.stats["chunk_reads"] == 0  # nothing read on opening
    np.testing.assert_array_equal(np.asarray(w.data), v.data)
    np.testing.assert_allclose(w.affine, v.affine, atol=1e-12)
    assert (w.modality, w.units) == ("CT", "HU")
    c = volumen.load(p, level=1)
    assert c.shape == (20, 18, 15)
    # level-1 voxel (0,0,0) is the mean of level-0 voxels 0..1 on every axis: centred on index 0.5
    np.testing.assert_allclose(c.affine[:3, 3], v.index_to_world(np.array([0.5, 0.5, 0.5])), atol=1e-12)
    assert c.data[0, 0, 0] == np.rint(v.data[:2, :2, :2].mean())


def test_plain_ome_scale_translation(tmp_path):
    """An OME-Zarr written by another tool (no volumen attributes): scale/translation -> RAS affine."""
    g = zarr.open_group(str(tmp_path / "x.zarr"), mode="w", zarr_format=2)
    a = g.create_array("0", shape=(1, 8, 9, 10), chunks=(1, 4, 4, 4), dtype="uint8")
    a[:] = 7
    g.attrs["multiscales"] = [{"version": "0.4", "axes": [{"name": n} for n in "czyx"], "datasets": [
        {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 2.0, 0.5, 0.25]},
                                                   {"type": "translation", "translation": [0, 10, 20, 30]}]}]}]
    v = volumen.load(tmp_path / "x.zarr")
    assert v.shape == (8, 9, 10) and v.spacing == (2.0, 0.5, 0.25)
    np.testing.assert_allclose(v.affine, [[0.25, 0, 0, 30], [0, 0.5, 0, 20], [0, 0, 2.0, 10], [0, 0, 0, 1]])
    assert int(v.data[3, 4, 5]) == 7


def test_slices_read_only_their_chunks(tmp_path):
    v = _volume()
    volumen.save(v, tmp_path / "t.ome.zarr", chunks=8)
    w = volumen.load(tmp_path / "t.ome.zarr")
    can_w, can_v = canonical(w), canonical(v)
    for plane in ("axial", "coronal", "sagittal"):
        w.data.stats["chunk_reads"] = 0
        img, sp = slice_at(w, plane, 5, canonical_volume=can_w)
        ref, sp_ref = slice_at(v, plane, 5, canonical_volume=can_v)
        np.testing.assert_array_equal(img, ref)
        assert sp == sp_ref
        # one chunk deep across the plane: 5 x 5 x 4 chunks of 8 cover (40, 36, 30); a plane cuts at most 5 * 5
        assert w.data.stats["chunk_reads"] <= 25, (plane, w.data.stats["chunk_reads"])
    assert w.data.stats["chunk_reads"] < 5 * 5 * 4


def test_an_axis_of_one_sample_repeats_lazily(tmp_path):
    """``np.repeat`` of a chunked plane's axis of one sample (``Volume.slab``) is a lazy view: nothing is read
    until it is, then it is NumPy's repeat, whole or sliced; another axis is a one-line error."""
    v = Volume(np.arange(2 * 30 * 20, dtype=np.int16).reshape(2, 30, 20), spacing=(5.0, 0.5, 0.5))
    volumen.save(v, tmp_path / "p.ome.zarr", chunks=8)
    plane = volumen.load(tmp_path / "p.ome.zarr").data[1:2]
    twice = np.repeat(plane, 2, axis=0)
    assert twice.shape == (2, 30, 20) and plane.stats["chunk_reads"] == 0
    ref = np.repeat(v.data[1:2], 2, axis=0)
    np.testing.assert_array_equal(np.asarray(twice), ref)
    np.testing.assert_array_equal(twice[:, 3:17, 5:].read(), ref[:, 3:17, 5:])
    np.testing.assert_array_equal(twice.transpose(2, 1, 0).read(), ref.transpose(2, 1, 0))
    with pytest.raises(ValueError, match="axis of one sample"):
        np.repeat(plane, 2, axis=1)


def test_not_zarr_is_a_typed_error(tmp_path):
    p = tmp_path / "bad.zarr"
    p.mkdir()
    (p / "zarr.json").write_text("{not json")
    with pytest.raises(CorruptDataError, match="bad.zarr"):
        volumen.load(p)


def test_a_chunked_volume_is_ray_cast_on_the_cpu_only(tmp_path):
    """``volumen.render`` draws a chunked volume out of core (tests/scale/test_outofcore.py); the techniques and
    devices that need the whole volume in memory are a one-line error, before any chunk is read."""
    from volumen.core import Camera, Scene
    from volumen.render import render

    volumen.save(_volume(), tmp_path / "t.ome.zarr", chunks=16)
    w = volumen.load(tmp_path / "t.ome.zarr")
    for how in ({"technique": "slicing"}, {"technique": "mesh"}, {"device": "gl"}):
        with pytest.raises(ValueError, match="ray cast out of core on the cpu"):
            render(Scene(volume=w), Camera.orbit(w), (8, 8), **how)
    assert w.data.stats["chunk_reads"] == 0


def test_chunk_cache_keeps_derived_entries_under_its_bound():
    """Chunks and derived entries share one least-recently-used byte budget; a derived entry is refused rather
    than drop what the current frame used (or when it is larger than the bound)."""
    from volumen.io import ChunkCache

    class Source:  # 8 chunks of 8 int16 (16 bytes)
        shape, dtype, chunks = (64,), np.dtype(np.int16), (8,)

        def __getitem__(self, key):
            return np.arange(64, dtype=np.int16)[key]

    cache = ChunkCache(Source(), 64)
    cache.new_frame()
    assert cache[(slice(1, 3),)].tolist() == [1, 2] and cache[(slice(8, 16),)][0] == 8
    assert cache.keep(("d",), "derived", 32) and cache.bytes == 64 and cache.derived(("d",)) == "derived"
    assert not cache.keep(("big",), "too big", 65)
    cache.new_frame()
    cache[(slice(16, 17),)]  # a chunk always finds room: the oldest entry (chunk 0) goes
    assert cache.misses == 3 and cache.bytes == 64
    assert not cache.keep(("e",), "refused", 64)  # would drop chunk 2 too, used this frame
    assert cache.keep(("e",), "kept", 32) and cache.derived(("d",)) is None  # drops chunk 1 and d (last frame's)
    assert cache.peak == 64 and cache.derived_hits == 1


def test_a_pyramid_of_floats_near_their_lowest_stays_finite(tmp_path):
    """A resampler's fill of the lowest float32 outside the field of view: the coarser levels' 2x2x2 means were
    summed in float32 and overflowed to -inf; summed in float64 each level holds the fill itself."""
    from volumen.data import fill_outside_field, phantom

    low = float(np.finfo(np.float32).min)
    v = fill_outside_field(phantom("head", size=32), low)
    volumen.save(v, tmp_path / "f.ome.zarr", chunks=8)
    for level in (1, 2):
        d = np.asarray(volumen.load(tmp_path / "f.ome.zarr", level=level).data)
        assert np.isfinite(d).all() and d.min() == np.float32(low)


def test_a_pyramid_keeps_a_fill_out_of_the_tissues_means(tmp_path):
    """An MRI filled with -1000 or -1e6 outside its field of view: the coarser levels leave the fill out of their
    2x2x2 means (``core.display_range`` cuts it off level 0), so their display ranges start at the MRI's noise
    floor as level 0's does. Averaged in, the fill made a band of values between at the field of view's edge
    (about a tenth of a coarse level's voxels), and levels 1 and 2 started their ranges at -750,000 and -937,500
    (fill -1e6): the milky cylinder again, wherever a coarse level is drawn."""
    from volumen.core import display_range
    from volumen.data import fill_outside_field, phantom

    mr = phantom("mr_head", size=64, dtype="float32")
    for fill in (-1000.0, -1e6):
        volumen.save(fill_outside_field(mr, fill), tmp_path / "m.ome.zarr", chunks=16)
        for level in (0, 1, 2):
            lo, hi = display_range(volumen.load(tmp_path / "m.ome.zarr", level=level))
            assert 0.0 <= lo <= 0.05 * hi, (fill, level, lo, hi)
        d = np.asarray(volumen.load(tmp_path / "m.ome.zarr", level=1).data)
        assert d.min() == np.float32(fill) and not np.any((d > fill) & (d < 0))
