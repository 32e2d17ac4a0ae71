"""`volumen render`: pictures reproduce bit for bit from --save-settings; flags fill the same objects."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image as PILImage

from volumen.cli import main
from volumen.cli._render import parse_light


def _png(path) -> np.ndarray:
    return np.asarray(PILImage.open(path))


def test_saved_settings_reproduce_the_picture_bit_for_bit(tmp_path):
    first, again = tmp_path / "a.png", tmp_path / "b.png"
    settings = tmp_path / "s.json"
    argv = ["render", "phantom:sphere", "-o", str(first), "--size", "40x32", "--preset", "ct-bone",
            "--azimuth", "30", "--elevation", "15", "--spv", "1.5", "--light", "pos=100,100,100 exp=4 dir=-1,-1,-1",
            "--clip-plane", "point=0,0,0 normal=0,0,1", "--adaptive", "--save-settings", str(settings)]
    assert main(argv) == 0
    assert main(["render", "--settings", str(settings), "-o", str(again)]) == 0
    a, b = _png(first), _png(again)
    assert a.shape == (32, 40, 3)
    assert a.any(), "the picture is black"
    np.testing.assert_array_equal(a, b)
    saved = json.loads(settings.read_text())
    assert saved["scene"]["shading"]["mode"] == "phong" and len(saved["scene"]["lights"]) == 1
    assert saved["scene"]["clipping"]["planes"][0]["normal"] == [0.0, 0.0, 1.0]
    assert saved["scene"]["sampling"]["adaptive"] is True
    assert saved["orbit"] == {"azimuth": 30.0, "elevation": 15.0}


def test_flags_override_settings(tmp_path):
    settings = tmp_path / "s.json"
    assert main(["render", "phantom:sphere", "-o", str(tmp_path / "a.png"), "--size", "24x24",
                 "--save-settings", str(settings)]) == 0
    assert main(["render", "--settings", str(settings), "-o", str(tmp_path / "m.png"), "--mode", "mip",
                 "--save-settings", str(tmp_path / "m.json")]) == 0
    m = json.loads((tmp_path / "m.json").read_text())
    assert m["scene"]["mode"] == "mip" and m["size"] == [24, 24]
    # MIP of the sphere phantom (1000 HU inside, through the saved ct-bone colours): bright in the middle, black corners
    img = _png(tmp_path / "m.png").astype(float).mean(axis=2)
    assert img[12, 12] > 100 and img[0, 0] < 10


def test_light_spec_parsing():
    light = parse_light("pos=1,2,3 dir=0,0,-2 exp=8 color=1,0.5,0 intensity=2")
    assert light.position == (1.0, 2.0, 3.0)
    assert light.direction == (0.0, 0.0, -2.0)  # kept as given; renderers normalize
    assert light.exponent == 8.0 and light.intensity == 2.0 and light.color == (1.0, 0.5, 0.0)
    with pytest.raises(ValueError, match="pos="):
        parse_light("exp=2")
    with pytest.raises(ValueError, match="unknown key"):
        parse_light("pos=1,2,3 cone=4")


def test_render_errors_are_one_line(tmp_path, capsys):
    assert main(["render", "-o", str(tmp_path / "x.png")]) == 1
    assert "INPUT" in capsys.readouterr().err
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    assert main(["render", "--settings", str(bad), "-o", str(tmp_path / "x.png")]) == 1
    assert "not a volumen render settings file" in capsys.readouterr().err


def test_light_spec_words_and_shading_flags(tmp_path):
    light = parse_light("kind=headlight attach=camera intensity=0.5")
    assert light.kind == "headlight" and light.attach == "camera" and light.intensity == 0.5
    with pytest.raises(ValueError, match="attach= must be one of world, camera"):
        parse_light("pos=0,0,0 attach=eye")
    settings = tmp_path / "s.json"
    assert main(["render", "phantom:sphere", "-o", str(tmp_path / "a.png"), "--size", "24x24", "--shading",
                 "scattering", "--light", "pos=100,100,100", "--sigma-a", "0.5", "--phase-g", "0.3",
                 "--save-settings", str(settings)]) == 0
    shading = json.loads(settings.read_text())["scene"]["shading"]
    assert shading["mode"] == "scattering" and shading["scattering"] == {"sigma_a": 0.5, "sigma_s": 1.0, "phase_g": 0.3}


def test_settings_keep_device_technique_and_reading_options(tmp_path):
    """The device, the technique with its options and every reading option that decided the picture are saved
    and used again (bit for bit); a settings file of volumen 0.1 (``"backend": "slicing-uint8"``) still reads."""
    import volumen
    from volumen.core import Volume

    data = np.full((12, 12, 12), -1000.0, np.float32)
    data[3:9, 3:9, 3:9] = 1000.0
    data[0, 0, 0] = np.nan  # replaced by the finite minimum with --nonfinite min, by 0 with the default
    volumen.save(Volume(data), tmp_path / "v.nrrd")
    settings = tmp_path / "s.json"
    argv = ["render", str(tmp_path / "v.nrrd"), "-o", str(tmp_path / "a.png"), "--size", "24x24",
            "--technique", "slicing", "--slicing-precision", "uint8", "--nonfinite", "min",
            "--save-settings", str(settings)]
    assert main(argv) == 0
    saved = json.loads(settings.read_text())
    assert saved["device"] == "gl" and saved["load"]["nonfinite"] == "min"
    assert saved["technique"]["name"] == "slicing" and saved["technique"]["options"]["precision"] == "uint8"
    assert main(["render", "--settings", str(settings), "-o", str(tmp_path / "b.png")]) == 0
    np.testing.assert_array_equal(_png(tmp_path / "a.png"), _png(tmp_path / "b.png"))
    old = {k: v for k, v in saved.items() if k not in ("device", "technique")} | {"backend": "slicing-uint8"}
    (tmp_path / "old.json").write_text(json.dumps(old))
    assert main(["render", "--settings", str(tmp_path / "old.json"), "-o", str(tmp_path / "c.png")]) == 0
    np.testing.assert_array_equal(_png(tmp_path / "a.png"), _png(tmp_path / "c.png"))


def test_technique_flags_are_checked(tmp_path, capsys):
    """An option of another technique, or a device the technique cannot use, fails in one line naming both."""
    out = str(tmp_path / "x.png")
    assert main(["render", "phantom:sphere", "-o", out, "--size", "8x8", "--mesh-shading", "gouraud"]) == 1
    assert "--mesh-shading is an option of --technique mesh, not raycast" in capsys.readouterr().err
    assert main(["render", "phantom:sphere", "-o", out, "--size", "8x8", "--technique", "mesh", "--device",
                 "cpu"]) == 1
    assert "technique 'mesh' runs on gl (or auto), not 'cpu'" in capsys.readouterr().err


def test_the_mesh_technique_draws_the_isosurface_it_names(tmp_path, capsys):
    """The mesh technique draws an isosurface: a scene of the default mode becomes one at the volume's default
    level (300 HU in a CT), said on the output line; another mode asked for is refused in one line."""
    out = str(tmp_path / "m.png")
    assert main(["render", "phantom:head?size=32", "-o", out, "--size", "16x16", "--technique", "mesh"]) == 0
    assert "isosurface at 300 (the mesh technique's)" in capsys.readouterr().out
    assert main(["render", "phantom:head?size=32", "-o", out, "--size", "16x16", "--technique", "mesh", "--mode",
                 "composite"]) == 1
    assert "--technique mesh draws an isosurface, not --mode composite" in capsys.readouterr().err


def test_unreadable_inputs_and_outputs_name_the_file(tmp_path, capsys):
    assert main(["render", "phantom:sphere", "-o", str(tmp_path / "x.png"), "--tf", str(tmp_path / "no.json")]) == 1
    assert "no.json" in capsys.readouterr().err
    assert main(["render", "phantom:sphere", "-o", str(tmp_path / "nowhere" / "x.png"), "--size", "8x8"]) == 1
    err = capsys.readouterr().err
    assert "nowhere" in err and "Traceback" not in err


def test_render_a_colour_dicom_shows_its_colours(tmp_path):
    """pydicom's two-frame RGB colour bars render in colour: the TF gives opacity (of the luminance), the
    voxels their colour; a grey picture would have every pixel's channels equal."""
    from pydicom.data import get_testdata_file

    from volumen.core import TransferFunction

    src = get_testdata_file("SC_rgb_rle_2frame.dcm")
    tf = tmp_path / "tf.json"
    tf.write_text(TransferFunction(color=((0, 1, 1, 1), (255, 1, 1, 1)), opacity=((0, 0), (8, 0.9), (255, 0.9)))
                  .to_json())
    out = tmp_path / "rgb.png"
    assert main(["render", src, "-o", str(out), "--size", "64x64", "--view", "superior", "--tf", str(tf),
                 "--shading", "none", "--no-jitter"]) == 0
    rgb = _png(out)[..., :3].astype(int)
    spread = rgb.max(axis=-1) - rgb.min(axis=-1)
    drawn = rgb.sum(axis=-1) > 0
    assert drawn.mean() > 0.3
    print(f"coloured share of the drawn pixels: {(spread[drawn] > 60).mean():.2f}")
    assert (spread[drawn] > 60).mean() > 0.2, "the picture is grey"  # 0.27 measured; grey: 0


def test_device_auto_says_which_device_it_took_and_why(tmp_path, capsys):
    """``--device auto`` names the device ``choose_device`` picks here and its reason, in one line."""
    from volumen.render import choose_device

    chosen, why = choose_device("auto", "raycast")
    assert main(["render", "phantom:sphere", "-o", str(tmp_path / "a.png"), "--size", "24x24", "--device", "auto"]) == 0
    assert f"device auto: {chosen} ({why})" in capsys.readouterr().out.splitlines()


def test_lit_shading_without_lights_warns_only_when_nothing_but_the_ambient_term_lights_it(tmp_path, capsys):
    """With no --light the default environment's studio rig lights the picture (no warning); a uniform
    environment leaves only the ambient term, which the warning says."""
    argv = ["render", "phantom:sphere", "-o", str(tmp_path / "a.png"), "--size", "24x24", "--shading", "phong"]
    assert main(argv) == 0
    assert "warning" not in capsys.readouterr().err
    assert main([*argv, "--environment", "uniform"]) == 0
    assert "only the ambient term lights the picture" in capsys.readouterr().err


def test_a_single_dicom_slice_is_drawn_face_on_as_its_mip_and_says_so(tmp_path, capsys):
    """pydicom's CT_small.dcm, one axial slice, with no flags: seen from the feet (``default_view``) as a thin-slab
    MIP (``default_mode``: its 5 mm composite is faint and dark), the mode's choice named on the summary line. The
    picture is the slice itself: more than a quarter of its pixels lit, its bone near white."""
    from pydicom.data import get_testdata_file

    out = tmp_path / "slice.png"
    assert main(["render", get_testdata_file("CT_small.dcm"), "-o", str(out), "--size", "64x64"]) == 0
    assert "mip (chosen for a slab)" in capsys.readouterr().out
    grey = _png(out).astype(float).mean(axis=2)
    print(f"lit share {np.mean(grey > 20):.2f}, mean {grey.mean():.1f}")
    assert np.mean(grey > 20) > 0.25 and grey.max() > 200
    assert main(["render", get_testdata_file("CT_small.dcm"), "-o", str(out), "--size", "64x64",
                 "--mode", "composite"]) == 0
    assert "(chosen for a slab)" not in capsys.readouterr().out


def test_a_colour_frame_is_drawn_as_its_image_and_says_so(tmp_path, capsys):
    """pydicom's RGB ultrasound frame with no flags: opaque and unshaded, both choices named on the summary line; the
    PNG shows the frame's colours (the mean of its lit pixels within 8 % of the frame's, a channel: drawn at half
    size, a dark pixel blends into its black neighbours; before, 7 % of the picture was lit, at a quarter of the
    frame's brightness); with --shading named the command line keeps it and names no shading choice."""
    from pydicom.data import get_testdata_file

    import volumen

    src = get_testdata_file("examples_rgb_color.dcm")
    out = tmp_path / "us.png"
    assert main(["render", src, "-o", str(out), "--size", "160x120"]) == 0
    line = capsys.readouterr().out
    assert "shading none (chosen for a colour slab)" in line and "preset mip-gray (chosen for a colour slab)" in line
    png = _png(out)[..., :3].astype(float)
    shown = png.sum(axis=2) > 0
    frame = np.asarray(volumen.load(src).data[0], float).reshape(-1, 3)
    frame = frame[frame.sum(axis=1) > 0]
    print(f"{shown.mean():.0%} of the picture; mean {png[shown].mean(axis=0).round(1)}, frame {frame.mean(axis=0)}")
    assert shown.mean() > 0.1
    assert np.all(np.abs(png[shown].mean(axis=0) - frame.mean(axis=0)) < 0.08 * frame.mean(axis=0))
    assert main(["render", src, "-o", str(out), "--size", "160x120", "--shading", "headlight"]) == 0
    line = capsys.readouterr().out
    assert "shading headlight, preset mip-gray (chosen for a colour slab)" in line, line


def test_labels_on_a_single_slice_are_composited_not_dropped(tmp_path, capsys):
    """``--labels`` asks for a composite (the labels colour it): a slab's default MIP drew none of them."""
    import nibabel as nib

    j, i = np.mgrid[:32, :32]
    scan = np.where(np.hypot(i - 15.5, j - 15.5) < 8, 300, -100).astype(np.int16)[None]  # (1, 32, 32) [z, y, x]
    for name, arr in (("ct", scan), ("seg", (scan > 0).astype(np.uint8))):
        nib.save(nib.Nifti1Image(arr.transpose(2, 1, 0), np.diag([1.0, 1.0, 5.0, 1.0])), str(tmp_path / f"{name}.nii"))
    out = tmp_path / "labels.png"
    assert main(["render", str(tmp_path / "ct.nii"), "--labels", str(tmp_path / "seg.nii"), "-o", str(out),
                 "--size", "48x48"]) == 0
    line = capsys.readouterr().out
    assert ", composite," in line and "chosen for a slab" not in line
    rgb = _png(out)[..., :3].astype(int)
    assert (rgb.max(axis=-1) - rgb.min(axis=-1) > 60).mean() > 0.05, "no label colour drawn"


def test_shift_moves_the_transfer_function_as_the_page_does(tmp_path, capsys):
    """``--shift 1000`` on a CT stored in scanner units (HU + 1000, not recognised as CT): the preset's inner control
    points move by 1000 (``TransferFunction.shifted``, what the browser page's shift slider does), said on the
    output line and kept in the settings."""
    import volumen
    from volumen.core import TransferFunction, Volume
    from volumen.data import phantom

    hu = phantom("sphere", size=24)
    raw = Volume((np.asarray(hu.data) + 1000).astype(np.int16), affine=hu.affine)
    volumen.save(raw, tmp_path / "raw.nrrd")
    settings = tmp_path / "s.json"
    assert main(["render", str(tmp_path / "raw.nrrd"), "-o", str(tmp_path / "a.png"), "--size", "24x24",
                 "--preset", "ct-bone", "--shift", "1000", "--save-settings", str(settings)]) == 0
    assert "preset ct-bone shifted by 1000" in capsys.readouterr().out
    saved = json.loads(settings.read_text())["scene"]["transfer"]
    assert saved == TransferFunction.preset("ct-bone").shifted(1000.0).to_dict()
