"""Vessel and airway analysis: cross-sections along a centerline, and the numbers a clinician reads off them.

* :func:`profile` -> :class:`Profile` -- at each centerline point the plane orthogonal to the path: lumen
  area, equivalent, minimum and maximum diameters (with their directions), the maximum inscribed sphere
  radius; branch points, path length, tortuosity; the stenosis (per cent diameter reduction against the
  healthy segments either side) and the maximum diameter, flagged. One data model for every front end:
  ``volumen measure vessel``, ``volumen fly --report``, the notebook (a table that shows itself);
* :func:`measure` -- the same from a lumen mask and a centerline already made;
* :class:`Lesion` -- a stenosis or a maximum; :func:`write_report` -- ``profile.csv``, ``report.json`` and
  ``profile.png`` into a folder.

SciPy, scikit-image and matplotlib are imported by the functions that need them.
"""

from ._lesions import Lesion
from ._profile import Profile, measure, profile
from ._report import write_report

__all__ = ["profile", "Profile", "measure", "Lesion", "write_report"]
