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
