"""Branch points along a centerline: where the lumen crosses a sphere round the path in more than two places.

Round a point of a tube, a sphere a little wider than the tube meets its lumen twice: ahead and behind.
Where a side branch leaves, it meets it a third time (and at a bifurcation, the two daughters and the
parent). :func:`branch_points` samples the lumen mask (nearest voxel) on a sphere of :data:`SHELL` local
radii (and a voxel more) round each centerline point, at :data:`SAMPLES` points spread evenly
(a Fibonacci lattice), joins neighbouring samples inside the lumen into patches and counts the patches
at least a voxel across. The points with more than two make stretches of the path; each stretch's middle
is a branch point.
"""

from __future__ import annotations

from functools import cache

import numpy as np

__all__ = ["branch_points", "SHELL", "SAMPLES"]

#: the sphere's radius, in local lumen radii (one voxel more)
SHELL = 1.6
#: points on the sphere
SAMPLES = 1200


@cache
def _sphere(n: int) -> tuple[np.ndarray, object]:
    """``n`` unit vectors of a Fibonacci lattice and the sparse graph joining each to its neighbours."""
    from scipy.sparse import coo_matrix
    from scipy.spatial import cKDTree

    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0 ** 0.5) * k
    r = np.sqrt(1.0 - z * z)
    unit = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
    spacing = np.sqrt(4.0 * np.pi / n)
    pairs = cKDTree(unit).query_pairs(1.8 * spacing, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n)).tocsr()
    return unit, graph


def _patches(volume, lumen: np.ndarray, point, radius: float) -> int:
    """How many patches at least a voxel across the lumen makes on the sphere ``radius`` mm round ``point``."""
    from scipy.sparse.csgraph import connected_components

    unit, graph = _sphere(SAMPLES)
    ijk = np.rint(volume.world_to_index(point + radius * unit)).astype(int)[:, ::-1]
    ok = np.all((ijk >= 0) & (ijk < lumen.shape), axis=1)
    inside = np.zeros(len(unit), bool)
    inside[ok] = lumen[tuple(ijk[ok].T)]
    if not inside.any():
        return 0
    idx = np.flatnonzero(inside)
    _, labels = connected_components(graph[idx][:, idx], directed=False)
    sizes = np.bincount(labels)
    voxel = float(min(volume.spacing))
    least = max(3, int(np.ceil(np.pi * (0.5 * voxel) ** 2 / (4.0 * np.pi * radius ** 2) * len(unit))))
    return int(np.sum(sizes >= least))


def branch_points(volume, lumen: np.ndarray, centerline, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(counts, arcs)``: per centerline point the patches the lumen makes on its sphere, and the arc lengths
    (mm) of the branch points, the middles of the stretches with more than two."""
    voxel = float(min(volume.spacing))
    counts = np.array([_patches(volume, lumen, p, SHELL * max(float(r), voxel) + voxel)
                       for p, r in zip(centerline.points, radius, strict=True)])
    many = np.concatenate([[0], (counts > 2).astype(np.int8), [0]])
    edges = np.flatnonzero(np.diff(many))
    arcs = np.array([0.5 * (centerline.arc[a] + centerline.arc[b - 1]) for a, b in zip(edges[::2], edges[1::2],
                                                                                        strict=True)])
    return counts, arcs
