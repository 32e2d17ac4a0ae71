"""Issue 23: virtual endoscopy on anatomy the lumen estimate was not tuned on, from ``--start`` and ``--end`` alone
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
