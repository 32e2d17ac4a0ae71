"""The app on a colour volume: the 3-D view draws the voxels' colours, no "Rendering failed"."""

from __future__ import annotations

import numpy as np

from volumen.core import Volume


def test_colour_volume_renders_in_colour(make_window):
    n = 40
    z, y, x = np.mgrid[:n, :n, :n]
    rgb = np.zeros((n, n, n, 3), np.uint8)
    rgb[(x - 12) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 <= 64] = (255, 0, 0)
    cube = (x >= 24) & (x <= 34) & (y >= 14) & (y <= 26) & (z >= 14) & (z <= 26)
    rgb[cube] = (40, 40, 255)  # luminance 64: past the default table's transparent tenth
    win = make_window(load=False)
    win.set_volume(Volume(rgb, spacing=(1, 1, 1)), "colour-phantom")
    assert win.wait_for_final(120) and win.last_error is None, win.last_error
    pic = win.view3d.frame.rgb.astype(int)
    red = (pic[..., 0] > 40) & (pic[..., 0] > 2 * pic[..., 2])
    blue = (pic[..., 2] > 40) & (pic[..., 2] > 2 * pic[..., 0]) & (pic[..., 2] > 2 * pic[..., 1])
    print(f"red pixels {red.mean():.3f}, blue pixels {blue.mean():.3f}")
    assert red.mean() > 0.01 and blue.mean() > 0.01


def test_an_ultrasound_frame_opens_as_its_image_and_a_volume_lit_again(make_window):
    """pydicom's RGB ultrasound frame opens as the command line draws it: composited opaque and unshaded (its own
    colours; the headlight over ``mr-default`` showed 7 % of it at a quarter of its brightness), the 3-D view's lit
    pixels about as bright as the frame's; the next scalar volume is lit by the headlight again. Between scalar
    volumes the lighting the user chose carries over."""
    from pydicom.data import get_testdata_file

    import volumen
    from volumen.core import Shading
    from volumen.data import phantom

    win = make_window(load=False)
    win.set_volume(phantom("head", size=(24, 24, 24)), "phantom:head?size=24")
    win.state.update_scene(shading=Shading(mode="phong"))
    win.set_volume(phantom("head", size=(20, 20, 20)), "phantom:head?size=20")
    assert win.state.scene.shading.mode == "phong"
    frame = volumen.load(get_testdata_file("examples_rgb_color.dcm"))
    win.set_volume(frame, "examples_rgb_color.dcm")
    assert win.wait_for_final(120) and win.last_error is None, win.last_error
    state = win.state
    assert state.scene.shading.mode == "none" and state.scene.mode == "composite"
    pic = win.view3d.frame.rgb.astype(float)
    lit = pic.sum(axis=2) > 30
    own = np.asarray(frame.data[0], float).reshape(-1, 3)
    own = own[own.sum(axis=1) > 30]
    print(f"lit {lit.mean():.2f} of the view, mean {pic[lit].mean():.1f} against the frame's {own.mean():.1f}")
    assert lit.mean() > 0.1 and abs(pic[lit].mean() - own.mean()) < 0.15 * own.mean()
    win.set_volume(phantom("head", size=(24, 24, 24)), "phantom:head?size=24")
    assert win.wait_for_final(120) and state.scene.shading.mode == "headlight"
