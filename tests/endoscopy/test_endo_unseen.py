"""Virtual endoscopy on anatomy the lumen estimate was not tuned on, from ``--start`` and ``--end`` alone
and from a segmentation, scored by :func:`volumen.endoscopy.score_flight` (the definitions the report uses).

For each phantom of a failure class (the aortic arch beside the lungs, the airways in lung behind one-voxel walls, a
colon with tagged fluid under a fluid level, a vessel whose contrast falls 30 % along it; VMTK's aorta is scored
the same way in ``test_endo_aorta.py``):

* data only: lumen Dice against the truth >= 0.9, >= 95 % of keyframes inside the truth, >= 80 % of the sampled
  frames looking down the lumen (centre's median depth >= 2 x the border's);
* with the true lumen as the mask: the same, and >= 99 % of the wall pixels drawn within one voxel of the mask's
  boundary (first-hit depth against the mask's distance along the ray, across the surfaces).
"""

from __future__ import annotations

import numpy as np
import pytest

from volumen.endoscopy import checked_centerline, lumen_wall, make_flight, score_flight

FRAMES, SIZE = 10, (40, 40)
PHANTOMS = ["arch", "airways", "tagged_colon", "washout"]


@pytest.mark.parametrize("mode", ["data", "mask"])
@pytest.mark.parametrize("name", PHANTOMS)
def test_flythrough_scores(name, mode, unseen):
    vol = unseen(name)
    truth = next(t for t in vol.meta["truth"].values() if hasattr(t, "mask")).mask
    start, end = (vol.meta["truth"]["landmarks"][k] for k in ("start", "end"))
    wall = lumen_wall(vol, start, end, mask=truth if mode == "mask" else None)
    flight = make_flight(vol, wall, checked_centerline(vol, wall.mask, start, end))
    score = score_flight(vol, truth, flight, lumen=wall.mask, frames=FRAMES, size=SIZE)
    print(f"{name} {mode}: {score.row()}; {wall.estimate.describe()}; ratios {np.round(score.ratios, 1).tolist()}")
    assert score.dice >= 0.9 and score.keyframes_inside >= 0.95 and score.looking_down >= 0.8
    if mode == "mask":
        assert not wall.shape_only and score.wall_within_voxel >= 0.99


def _pixel(camera, point, width: int):
    """The pixel (row, column) of a square frame ``width`` wide that shows world ``point``, or None off the frame."""
    r, u, f = camera.basis()
    v = np.asarray(point, float) - np.asarray(camera.position, float)
    if v @ f <= 0:
        return None
    half = np.tan(np.radians(camera.fov) / 2)
    x, y = (v @ r) / (v @ f) / half, (v @ u) / (v @ f) / half
    px, py = int((x + 1) * width / 2), int((1 - y) * width / 2)
    return (py, px) if 0 <= px < width and 0 <= py < width else None


def test_bronchoscopy_shows_the_carina(unseen):
    """The README's bronchoscopy (``--lumen air`` from the trachea into the left main bronchus): some frame shows the
    carina as a ridge between the two main bronchi's openings: the ray toward the carina meets the ridge within
    12 mm beyond the branch point, nearer than the walls seen down either bronchus (12 mm in), and the flashlight's
    fall-off draws the ridge at least twice as bright as both openings."""
    from volumen.data._airways import CARINA, TREE

    vol = unseen("airways")
    start, end = (0.0, 1.0, 40.0), (-26.0, -8.0, -14.0)
    wall = lumen_wall(vol, start, end, kind="air")
    flight = make_flight(vol, wall, checked_centerline(vol, wall.mask, start, end))
    car = np.array(CARINA, float)
    openings = [car + 12.0 * (np.array(p, float) - car) / np.linalg.norm(np.array(p, float) - car)
                for p in (TREE["trachea_right"][0][2], TREE["left_main_lower"][0][1])]
    seen = []
    for pose in flight.path.play(frames=12):
        cam, img = flight.endoscope.camera(pose), flight.endoscope.render(pose, (64, 64))
        px = [_pixel(cam, p, 64) for p in (car, *openings)]
        if None in px:
            continue
        depth = [float(img.depth[p]) for p in px]
        light = [float(img.rgba[p][:3].mean()) for p in px]
        to_carina = float(np.linalg.norm(car - np.asarray(cam.position)))
        seen.append(depth[0] - to_carina < 12.0 and depth[0] < min(depth[1:]) and light[0] >= 2 * max(light[1:]))
        print(f"eye {np.round(pose.position, 1)}: depths {np.round(depth, 1)} mm (carina {to_carina:.1f} mm away), "
              f"brightness {np.round(light, 3)}")
    assert any(seen)
