"""Compiled breadth-first walk over a mesh's faces for ``_orient.py`` (arrays and scalars only)."""


import numpy as np

from ..jit import njit


@njit(cache=True)
def propagate(m, nbr_ptr, nbr, nbr_same, flip, comp):
    """Breadth-first walk over faces: flip each neighbour whose winding disagrees; label components."""
    queue = np.empty(m, np.int64)
    n_comp = 0
    for seed in range(m):
        if comp[seed] >= 0:
            continue
        comp[seed] = n_comp
        head, tail = 0, 1
        queue[0] = seed
        while head < tail:
            f = queue[head]
            head += 1
            for k in range(nbr_ptr[f], nbr_ptr[f + 1]):
                g = nbr[k]
                if comp[g] < 0:
                    comp[g] = n_comp
                    flip[g] = flip[f] ^ nbr_same[k]
                    queue[tail] = g
                    tail += 1
        n_comp += 1
    return n_comp
