"""The stored marching-cubes tables are the generator's output, and self-consistent."""

from __future__ import annotations

import numpy as np

from volumen.surface import _mc_tables as stored
from volumen.surface._mc_tablegen import EDGES, build


def test_stored_tables_equal_a_fresh_generation():
    fresh = build()
    for name, table in fresh.items():
        have = getattr(stored, name)
        assert have.dtype == table.dtype and np.array_equal(have, table), name


def test_triangles_use_only_crossed_edges_and_close_each_case():
    t = build()
    case_of = np.repeat(np.arange(256), 1 << t["AMB_COUNT"].astype(int))
    for v, case in enumerate(case_of):
        crossed = {e for e, (a, b) in enumerate(EDGES) if ((case >> a) & 1) != ((case >> b) & 1)}
        tris = t["VAR_TRIS"][v, : 3 * t["VAR_NTRI"][v]].reshape(-1, 3)
        used = set(tris.ravel().tolist()) - {12}
        assert used == crossed, (case, v)
        # inside the cube, edges between two vertices are shared by two triangles, except the
        # loop segments lying on cube faces (one triangle here, one in the neighbour)
        e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
        _, counts = np.unique(e, axis=0, return_counts=True)
        assert counts.max(initial=0) <= 2
