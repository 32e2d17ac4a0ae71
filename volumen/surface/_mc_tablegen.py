"""Generator of the face-consistent marching-cubes tables in ``_mc_tables.py``.

Run ``python -m volumen.surface._mc_tablegen > volumen/surface/_mc_tables.py`` to
regenerate them; ``tests/surface/test_mc_tables.py`` checks that the stored tables
equal a fresh run.

How the tables are built
------------------------
A cube's corners are numbered ``c = dx + 2 dy + 4 dz`` (offsets along x, y, z =
voxel axes i, j, k); a corner is *inside* when its value is above the iso level.
Edges 0-3 run along x (``dy + 2 dz``), 4-7 along y (``dx + 2 dz``), 8-11 along
z (``dx + 2 dy``).

For each of the 256 inside/outside patterns and each choice on its ambiguous faces
(a face whose inside corners are diagonal; the kernel decides it with the
asymptotic decider, ``f0 f2 > f1 f3``, from the face's four values only, so both
cubes sharing the face make the same choice) the generator

1. draws on every face the segments joining its crossed edges: they cut off the
   inside corners, or on an ambiguous face the corners of the sign the choice
   separates;
2. directs every segment so that, seen from outside the cube, the inside corners lie
   on its right; the segments then chain into closed, consistently directed loops;
3. triangulates each loop with the minimum-length triangulation that never joins
   two vertices lying on one cube face by a diagonal (such an edge could be claimed
   by the neighbouring cube too), so every mesh edge is either a face segment,
   shared with exactly one triangle of the neighbouring cube, or an inner diagonal,
   shared by two triangles of this cube.

The surface is therefore watertight wherever it is closed, and triangles wind
counter-clockwise seen from outside (their normals point to lower values). The
interior ambiguity of the cube (tunnels, Lewiner's cases 4, 6, 7, 10, 12, 13) is not
resolved: each loop is a disk, which keeps the mesh a closed 2-manifold.

References
----------
Nielson, G. M. and Hamann, B. "The asymptotic decider: resolving the ambiguity in
marching cubes", IEEE Visualization 1991.
Montani, C., Scateni, R. and Scopigno, R. "A modified look-up table for implicit
disambiguation of marching cubes", The Visual Computer 10, 1994.
"""

from __future__ import annotations

import numpy as np

CORNERS = np.array([(c & 1, (c >> 1) & 1, (c >> 2) & 1) for c in range(8)], dtype=float)  # (x, y, z)


def _edges() -> list[tuple[int, int]]:
    edges = []
    for k in range(4):  # along x
        dy, dz = k & 1, k >> 1
        c = 2 * dy + 4 * dz
        edges.append((c, c + 1))
    for k in range(4):  # along y
        dx, dz = k & 1, k >> 1
        c = dx + 4 * dz
        edges.append((c, c + 2))
    for k in range(4):  # along z
        dx, dy = k & 1, k >> 1
        c = dx + 2 * dy
        edges.append((c, c + 4))
    return edges


EDGES = _edges()
EDGE_OF = {frozenset(e): n for n, e in enumerate(EDGES)}
MID = np.array([(CORNERS[a] + CORNERS[b]) / 2 for a, b in EDGES])


def _faces() -> list[tuple[tuple[int, int, int, int], np.ndarray]]:
    """Six faces: four corners in cyclic order and the outward normal (x, y, z)."""
    faces = []
    for axis in range(3):
        u, v = [a for a in range(3) if a != axis]
        for side in (0, 1):
            ring = []
            for pu, pv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = [0, 0, 0]
                p[axis], p[u], p[v] = side, pu, pv
                ring.append(p[0] + 2 * p[1] + 4 * p[2])
            normal = np.zeros(3)
            normal[axis] = 1.0 if side else -1.0
            faces.append((tuple(ring), normal))
    return faces


FACES = _faces()
EDGE_FACES = [{f for f, (ring, _) in enumerate(FACES) if a in ring and b in ring} for a, b in EDGES]


def ambiguous_faces(case: int) -> list[int]:
    """Faces whose inside corners are the two ends of one diagonal."""
    out = []
    for f, (ring, _) in enumerate(FACES):
        s = [(case >> c) & 1 for c in ring]
        if s[0] == s[2] and s[1] == s[3] and s[0] != s[1]:
            out.append(f)
    return out


def _directed(a: int, b: int, normal: np.ndarray, corner: int, inside: bool) -> tuple[int, int]:
    """Direct the segment between edges a and b so inside corners lie on its right, seen from outside."""
    t = MID[b] - MID[a]
    side = np.dot(np.cross(normal, t), CORNERS[corner] - (MID[a] + MID[b]) / 2)
    # cross(normal, t) points to the segment's left seen from outside
    on_left = side > 0
    return (a, b) if on_left != inside else (b, a)


def face_segments(case: int, face: int, connect_inside: bool) -> list[tuple[int, int]]:
    """Directed segments (edge, edge) of one face for one case and one ambiguity choice."""
    ring, normal = FACES[face]
    inside = [(case >> c) & 1 == 1 for c in ring]
    crossed = [EDGE_OF[frozenset((ring[i], ring[(i + 1) % 4]))] for i in range(4)]
    flips = [i for i in range(4) if inside[i] != inside[(i + 1) % 4]]
    if not flips:
        return []
    if len(flips) == 2:
        a, b = crossed[flips[0]], crossed[flips[1]]
        i = (flips[0] + 1) % 4  # a corner between the two crossed edges: on one side of the segment
        return [_directed(a, b, normal, ring[i], inside[i])]
    # ambiguous: cut off the corners of the sign that is separated
    cut_sign = not connect_inside  # cut off inside corners when inside is separated
    segs = []
    for i in range(4):
        if inside[i] == cut_sign:
            a, b = crossed[(i - 1) % 4], crossed[i]  # the two edges meeting at corner i
            segs.append(_directed(a, b, normal, ring[i], inside[i]))
    return segs


def loops(case: int, choice: dict[int, bool]) -> list[list[int]]:
    """Closed directed loops of crossed edges for a case and choices {face: connect_inside}."""
    nxt: dict[int, int] = {}
    for f in range(6):
        for a, b in face_segments(case, f, choice.get(f, False)):
            if a in nxt:
                raise AssertionError(f"case {case}: edge {a} leaves twice")
            nxt[a] = b
    if sorted(nxt) != sorted(nxt.values()):
        raise AssertionError(f"case {case}: segments do not chain")
    out, seen = [], set()
    for start in sorted(nxt):
        if start in seen:
            continue
        loop, e = [], start
        while e not in seen:
            seen.add(e)
            loop.append(e)
            e = nxt[e]
        out.append(loop)
    return out


def _share_face(a: int, b: int) -> bool:
    return bool(EDGE_FACES[a] & EDGE_FACES[b])


def triangulate(loop: list[int]) -> list[tuple[int, int, int]] | None:
    """Minimum total diagonal length triangulation without diagonals inside a cube face, or None."""
    n = len(loop)
    inf = float("inf")

    def weight(i: int, j: int) -> float:
        if (j - i) % n in (1, n - 1):
            return 0.0  # a loop edge
        if _share_face(loop[i], loop[j]):
            return inf
        return float(np.linalg.norm(MID[loop[i]] - MID[loop[j]]))

    cost = [[0.0] * n for _ in range(n)]
    split = [[-1] * n for _ in range(n)]
    for gap in range(2, n):
        for i in range(n - gap):
            j = i + gap
            best, arg = inf, -1
            for k in range(i + 1, j):
                c = cost[i][k] + cost[k][j] + weight(i, k) + weight(k, j)
                if c < best:
                    best, arg = c, k
            cost[i][j], split[i][j] = best, arg
    if cost[0][n - 1] == inf:
        return None
    tris: list[tuple[int, int, int]] = []

    def emit(i: int, j: int) -> None:
        if j - i < 2:
            return
        k = split[i][j]
        tris.append((loop[i], loop[k], loop[j]))
        emit(i, k)
        emit(k, j)

    emit(0, n - 1)
    return tris


def build() -> dict[str, np.ndarray]:
    """All tables as arrays (see the module docstring for their meaning)."""
    amb = np.full((256, 6), -1, np.int8)
    amb_count = np.zeros(256, np.uint8)
    var_base = np.zeros(256, np.int32)
    edge_mask = np.zeros(256, np.uint16)
    variants: list[list[tuple[int, int, int]]] = []
    centres: list[list[int]] = []
    for case in range(256):
        faces = ambiguous_faces(case)
        amb[case, : len(faces)] = faces
        amb_count[case] = len(faces)
        var_base[case] = len(variants)
        for n, (a, b) in enumerate(EDGES):
            if ((case >> a) & 1) != ((case >> b) & 1):
                edge_mask[case] |= 1 << n
        for code in range(1 << len(faces)):
            # bit q of the variant number is the choice (connect inside corners) on faces[q]
            choice = {f: bool((code >> q) & 1) for q, f in enumerate(faces)}
            tris: list[tuple[int, int, int]] = []
            fans: list[int] = []
            for loop in loops(case, choice):
                safe = triangulate(loop)
                if safe is None:  # a fan around a centre vertex (index 12 + n) of the loop's edges
                    centre = 12 + len(fans)
                    fans.append(sum(1 << e for e in loop))
                    safe = [(loop[i], loop[(i + 1) % len(loop)], centre) for i in range(len(loop))]
                tris.extend(safe)
            variants.append(tris)
            centres.append(fans)
    max_tri = max(len(v) for v in variants)
    tri = np.full((len(variants), 3 * max_tri), -1, np.int8)
    ntri = np.zeros(len(variants), np.uint8)
    for v, tris in enumerate(variants):
        ntri[v] = len(tris)
        tri[v, : 3 * len(tris)] = np.array(tris, np.int8).ravel() if tris else []
    max_centre = max(len(c) for c in centres)
    ncentre = np.array([len(c) for c in centres], np.uint8)
    centre_edges = np.zeros((len(variants), max_centre), np.uint16)
    for v, fans in enumerate(centres):
        centre_edges[v, : len(fans)] = fans
    face_corners = np.array([ring for ring, _ in FACES], np.int8)
    return dict(EDGE_CORNERS=np.array(EDGES, np.int8), FACE_CORNERS=face_corners, AMB_FACES=amb,
                AMB_COUNT=amb_count, VAR_BASE=var_base, EDGE_MASK=edge_mask, VAR_NTRI=ntri, VAR_TRIS=tri,
                VAR_NCENTRE=ncentre, VAR_CENTRE_EDGES=centre_edges)


def _wrap(tokens: list[str], width: int = 96) -> str:
    chunks, cur = [], ""
    for tok in tokens:
        if cur and len(cur) + len(tok) + 1 > width:
            chunks.append(cur)
            cur = tok
        else:
            cur = f"{cur} {tok}" if cur else tok
    chunks.append(cur)
    return "\n".join(f'    "{c} "' for c in chunks)


def render_module(tables: dict[str, np.ndarray]) -> str:
    """Python source of ``_mc_tables.py``.

    Integer tables are flat strings of numbers; ``VAR_TRIS`` is one token per variant,
    a hexadecimal digit per triangle corner (edges 0-11 = ``0``-``b``, the centre
    vertex = ``c``; ``-`` for no triangle), decoded into a -1-padded array.
    """
    lines = [
        '"""Face-consistent marching-cubes tables. GENERATED by volumen.surface._mc_tablegen: do not edit.',
        "",
        "Regenerate with ``python -m volumen.surface._mc_tablegen > volumen/surface/_mc_tables.py``.",
        "See the generator's docstring for the corner, edge and face numbering and how the tables are built.",
        '"""',
        "",
        "import numpy as np",
        "",
        "",
        "def _t(dtype, shape, text):",
        "    return np.array(text.split(), dtype=dtype).reshape(shape)",
        "",
        "",
        "def _tris(width, text):",
        "    tokens = text.split()",
        "    out = np.full((len(tokens), width), -1, np.int8)",
        "    for v, tok in enumerate(tokens):",
        "        if tok != \"-\":",
        "            out[v, : len(tok)] = [int(c, 16) for c in tok]",
        "    return out",
        "",
    ]
    for name, arr in tables.items():
        if name == "VAR_TRIS":
            tokens = ["".join(format(int(e), "x") for e in row if e >= 0) or "-" for row in arr]
            lines.append(f"{name} = _tris({arr.shape[1]}, (\n{_wrap(tokens)}\n))")
        else:
            tokens = [str(int(x)) for x in arr.ravel()]
            lines.append(f"{name} = _t(np.{arr.dtype.name}, {tuple(arr.shape)}, (\n{_wrap(tokens)}\n))")
        lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    print(render_module(build()), end="")
