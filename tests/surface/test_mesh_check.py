"""``check_mesh`` (``volumen mesh --check``): open and non-manifold edges, pieces and genus, on meshes whose
answers are known by construction: a torus of quads (genus 1), a tetrahedron (genus 0) (the sphere's marching
cubes: tests/cli/test_cli_mesh.py), and what breaks each: a removed triangle, a fin on an edge,
corners at one position."""

from __future__ import annotations

import numpy as np

from volumen.surface import Mesh, check_mesh

_TETRA_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
_TETRA_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], np.int32)


def _torus(n: int = 24, m: int = 12, big: float = 30.0, small: float = 10.0) -> Mesh:
    """A closed torus: an n x m grid of quads wrapped both ways, two triangles each."""
    u, w = np.meshgrid(np.arange(n) * 2 * np.pi / n, np.arange(m) * 2 * np.pi / m, indexing="ij")
    v = np.stack([(big + small * np.cos(w)) * np.cos(u), (big + small * np.cos(w)) * np.sin(u), small * np.sin(w)],
                 axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return Mesh(v, f.astype(np.int32))


def test_closed_meshes_have_no_open_edges_and_their_genus():
    torus = check_mesh(_torus())
    assert torus.closed and torus.genus == 1 and torus.pieces == 1 and torus.edges == 3 * 24 * 12
    tetra = check_mesh(Mesh(_TETRA_V, _TETRA_F))
    assert tetra.closed and tetra.genus == 0 and tetra.edges == 6 and tetra.triangles == 4
    two = check_mesh(Mesh(np.concatenate([_TETRA_V, _TETRA_V + 5]), np.concatenate([_TETRA_F, _TETRA_F + 4])))
    assert two.closed and two.pieces == 2 and two.genus == 0
    assert "closed: 0 open edges, 0 non-manifold edges of 6, 1 pieces, genus 0" in tetra.line()


def test_holes_and_fins_are_counted():
    t = _torus()
    holed = check_mesh(Mesh(t.vertices, t.faces[1:]))
    assert not holed.closed and holed.open_edges == 3 and holed.genus is None
    fin_v = np.concatenate([_TETRA_V, [[1, 1, 1]]]).astype(np.float32)
    fin = check_mesh(Mesh(fin_v, np.concatenate([_TETRA_F, [[0, 1, 4]]])))  # a third triangle on edge 0-1
    assert fin.nonmanifold_edges == 1 and fin.open_edges == 2 and "open:" in fin.line()


def test_corners_at_one_position_are_welded_as_an_stl_reader_does():
    v = np.concatenate([_TETRA_V, _TETRA_V[:1]])  # vertex 4 lies on vertex 0
    f = _TETRA_F.copy()
    f[3] = [1, 2, 3]
    f[0] = [4, 2, 1]  # one face names the copy: welded, the tetrahedron is closed
    assert check_mesh(Mesh(v, f)).closed
    collapsed = check_mesh(Mesh(v, np.concatenate([f, [[0, 4, 1]]])))  # two corners on one point
    assert collapsed.collapsed == 1 and collapsed.closed
