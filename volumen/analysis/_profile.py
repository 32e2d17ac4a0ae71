"""The profile of a vessel or airway: its cross-sections along the centerline, and what a clinician reads off them.

:func:`profile` is what every front end calls (``volumen measure vessel``, ``volumen fly --report``, the
notebook): from a start and an end point alone (the lumen grown as ``volumen fly`` grows it, the centerline
between the points), or from a lumen mask and/or a centerline already made. Then (:func:`measure`):

1. the sections along the centerline (:func:`._sections.measure_sections`; a grown lumen's wall drawn at
   each section's own half-way value, and a contrast lumen redrawn in 3D at those values,
   :func:`volumen.endoscopy.locally_thresholded`, for the inscribed spheres and the branch points: an air lumen
   is not, its thin walls would let the redrawn lumen through into the air-like lung);
2. the branch points (:func:`._branches.branch_points`);
3. the centerline moved onto the sections' centroids (smoothed over :data:`RECENTRE_SIGMA` mm, by at most
   half the local radius, branch stretches kept), the sections measured again there: a centerline that
   ran off the axis of a lumen grown short of a dim layer of contrast tilts its planes, and the sections
   of a tilted plane are too wide;
4. the stenosis and the maximum (:mod:`._lesions`), the path length and its tortuosity
   (``length / chord - 1``, VMTK's ``Tortuosity``).

:class:`Profile` holds it all: a table (one row per section, :meth:`Profile.columns`), a summary
(:meth:`Profile.summary`), CSV and JSON, and in Jupyter a summary and the profile's plot
(``_repr_html_``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Profile", "profile", "measure", "RECENTRE_SIGMA"]

#: the sections' centroids are smoothed along the path by a Gaussian of this many mm before the centerline
#: is moved onto them
RECENTRE_SIGMA = 2.0


@dataclass(frozen=True, eq=False)
class Profile:
    """Cross-sections along a centerline (see the module docstring).

    Attributes
    ----------
    centerline : Centerline
        The path the sections are orthogonal to (world mm), one section per point.
    sections : Sections
        Area, equivalent, minimum and maximum diameters (with directions), inscribed sphere radius.
    branch_count : (N,) int
        Patches the lumen makes on the sphere round each point (2 in a plain tube).
    branch_arcs : (B,) float, mm
        Arc lengths of the branch points.
    stenosis, maximum : Lesion
    source : {"grown", "mask"}
        Whether the lumen was grown from the data (walls at each section's half-way value) or given.
    """

    centerline: object
    sections: object
    branch_count: np.ndarray
    branch_arcs: np.ndarray
    stenosis: object
    maximum: object
    source: str

    @property
    def length(self) -> float:
        """Path length, mm."""
        return self.centerline.length

    @property
    def tortuosity(self) -> float:
        """``length / chord - 1`` (0 for a straight path)."""
        chord = float(np.linalg.norm(self.centerline.points[-1] - self.centerline.points[0]))
        return self.length / chord - 1.0 if chord > 0 else float("inf")

    def columns(self) -> dict[str, np.ndarray]:
        """The table: column name (with its unit) -> one value per section."""
        s, p = self.sections, self.centerline.points
        cols = {"arc_mm": self.centerline.arc, "x_mm": p[:, 0], "y_mm": p[:, 1], "z_mm": p[:, 2],
                "area_mm2": s.area, "diameter_mm": s.diameter, "min_diameter_mm": s.min_diameter,
                "max_diameter_mm": s.max_diameter, "inscribed_radius_mm": s.inscribed_radius}
        for name, v in (("min", s.min_direction), ("max", s.max_direction)):
            cols.update({f"{name}_direction_{a}": v[:, k] for k, a in enumerate("xyz")})
        cols["branches"] = self.branch_count
        return cols

    def summary(self) -> dict:
        """The numbers of the whole path: length, tortuosity, diameters' range, branch points, the lesions."""
        s = self.sections
        return {"source": self.source, "length_mm": round(self.length, 1), "tortuosity": round(self.tortuosity, 3),
                "sections": len(s.area), "diameter_mm": [round(float(s.diameter.min()), 1),
                                                         round(float(s.diameter.max()), 1)],
                "max_diameter_mm": round(float(s.max_diameter.max()), 1),
                "inscribed_radius_mm": [round(float(s.inscribed_radius.min()), 1),
                                        round(float(s.inscribed_radius.max()), 1)],
                "branch_points_mm": [round(float(a), 1) for a in self.branch_arcs],
                "stenosis": self.stenosis.to_dict(), "maximum": self.maximum.to_dict()}

    def to_dict(self) -> dict:
        """JSON-ready: the summary and the table (mm to 0.01, directions to 0.001)."""
        table = {k: np.round(v.astype(float), 3 if "direction" in k else 2).tolist() for k, v in self.columns().items()}
        return {"summary": self.summary(), "table": table}

    def to_csv(self, path) -> None:
        """Write the table as CSV (a header of column names, one row per section)."""
        cols = self.columns()
        with open(path, "w", encoding="utf-8") as f:
            f.write(",".join(cols) + "\n")
            for row in zip(*cols.values(), strict=True):
                f.write(",".join(_cell(k, v) for k, v in zip(cols, row, strict=True)) + "\n")

    def plot(self, volume=None):
        """A matplotlib figure: diameters and area against the arc, the stenosis and the maximum marked, with
        the stretched CPR of ``volume`` above it when given (:func:`._figure.profile_figure`)."""
        from ._figure import profile_figure

        return profile_figure(self, volume)

    def _repr_html_(self) -> str:
        from ._figure import summary_html

        return summary_html(self)

    def __repr__(self) -> str:
        st, mx = self.stenosis, self.maximum
        return (f"Profile({len(self.sections.area)} sections, length {self.length:.1f} mm, diameter "
                f"{self.sections.diameter.min():.1f}..{self.sections.diameter.max():.1f} mm, stenosis "
                f"{st.percent:.0f} % at {st.arc:.1f} mm, maximum {mx.diameter:.1f} mm at {mx.arc:.1f} mm)")


def _cell(name: str, value) -> str:
    if name == "branches":
        return str(int(value))
    return f"{value:.3f}" if "direction" in name else f"{value:.2f}"


def _recentred(centerline, sections, branch_count):
    """The centerline moved onto the sections' smoothed centroids (see the module docstring), resampled at its
    own step."""
    from scipy.ndimage import gaussian_filter1d

    from ..endoscopy import Centerline

    step = float(np.median(np.diff(centerline.arc)))
    shift = sections.centroid - centerline.points
    shift[branch_count > 2] = 0.0
    size = np.linalg.norm(shift, axis=1, keepdims=True)
    limit = 0.5 * np.maximum(sections.inscribed_radius, 0.0)[:, None]
    shift = np.where(size > limit, shift * limit / np.maximum(size, 1e-12), shift)
    shift = gaussian_filter1d(shift, RECENTRE_SIGMA / step, axis=0, mode="nearest")
    moved = centerline.points + shift
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(moved, axis=0), axis=1))])
    s = np.linspace(0.0, arc[-1], max(int(round(arc[-1] / step)), 1) + 1)
    points = np.stack([np.interp(s, arc, moved[:, a]) for a in range(3)], axis=1)
    return Centerline(points, np.interp(s, arc, sections.inscribed_radius), s)


def measure(volume, lumen: np.ndarray, centerline, *, refine: bool) -> Profile:
    """The :class:`Profile` of ``lumen`` (bool ``[z, y, x]`` on ``volume``'s grid) along ``centerline``;
    ``refine``: the lumen was grown from the data, whose half-way values draw each section's wall."""
    from ..endoscopy import locally_thresholded
    from ._branches import branch_points
    from ._lesions import find_maximum, find_stenosis
    from ._sections import measure_sections

    first = measure_sections(volume, lumen, centerline, refine=refine)
    if refine and first.sign > 0:
        lumen = locally_thresholded(volume, lumen, centerline.points, first.threshold, first.sign)
    counts, _ = branch_points(volume, lumen, centerline, first.inscribed_radius)
    centerline = _recentred(centerline, first, counts)
    sections = measure_sections(volume, lumen, centerline, refine=refine)
    counts, arcs = branch_points(volume, lumen, centerline, sections.inscribed_radius)
    arc = centerline.arc
    exclude, segment = _near_branches(arc, counts, sections.diameter)
    exclude |= sections.area <= 0
    return Profile(centerline, sections, counts, arcs, find_stenosis(arc, sections.diameter, exclude, segment),
                   find_maximum(arc, sections.diameter, sections.max_diameter, exclude, segment),
                   "grown" if refine else "mask")


def _near_branches(arc, counts, diameter) -> tuple[np.ndarray, np.ndarray]:
    """``(near, segment)``: the sections within a local radius of a branch stretch (a plane there still cuts
    the branch's mouth), and an id per section counting the branch stretches before it."""
    branch = counts > 2
    near = branch.copy()
    for k in np.flatnonzero(branch):
        near |= np.abs(arc - arc[k]) <= 0.5 * diameter[k]
    starts = np.concatenate([[False], branch[1:] & ~branch[:-1]])
    return near, np.cumsum(starts)


def profile(volume, start=None, end=None, *, lumen=None, centerline=None, kind: str = "auto", value_range=None,
            threshold=None) -> Profile:
    """Cross-sections of the lumen between ``start`` and ``end`` (world RAS+ mm), as ``volumen measure vessel``.

    Parameters
    ----------
    volume : Volume
    start, end : (3,) float, world mm
        The path's ends (both needed unless ``centerline`` is given).
    lumen : (nz, ny, nx) bool, optional
        A segmentation of the lumen on ``volume``'s grid, measured as it is; None: grown from ``start``
        (:func:`volumen.endoscopy.lumen_wall`, ``kind``, ``value_range`` and ``threshold`` as there), each
        section's wall drawn at its own half-way value.
    centerline : Centerline, optional
        The path (a flight's); None: :func:`volumen.endoscopy.checked_centerline` between the points.

    Returns
    -------
    Profile

    Raises
    ------
    LumenError
        The points are in no lumen, the lumen leaks, the points are not joined through it.
    ValueError
        Neither the points nor a centerline are given.
    """
    from ..endoscopy import checked_centerline, lumen_wall

    if centerline is None and (start is None or end is None):
        raise ValueError("profile needs start and end points, or a centerline")
    if start is None:
        start, end = centerline.points[0], centerline.points[-1]
    refine = lumen is None
    if lumen is None:
        lumen = lumen_wall(volume, start, end, kind=kind, value_range=value_range, threshold=threshold).mask
    if centerline is None:
        centerline = checked_centerline(volume, lumen, start, end)
    return measure(volume, np.asarray(lumen, bool), centerline, refine=refine)
