"""Energy of a lattice's springs (`lattice.LatticeSprings`), compiled: each offset's springs
visited in grid order, with no list of springs.

The grid has shape (3,) in C order (2-D grids as (1, n0, n1), `stencil.padded_shape`)
and offsets (M, 3); spring m of particle p joins it to p + offset m, with the
stiffness and rest length of offset m.
"""

import math
from collections.abc import Callable

import numba
import numpy as np

from .equations import spring_energy


@numba.njit(cache=True, error_model="numpy")
def _plane_sum(x, shape, offsets, stiffness, rest_lengths, m, plane):
    """Σ over the springs of offset m from the particles of grid ``plane``: their energy
    ½ k (|d| - l)² (J), d = x_p - x_q, with k = ``stiffness[m]`` (N/m) and
    l = ``rest_lengths[m]`` (m)."""
    n1, n2 = shape[1], shape[2]
    o1, o2 = offsets[m, 1], offsets[m, 2]
    k, rest = stiffness[m], rest_lengths[m]
    shift = (offsets[m, 0] * n1 + o1) * n2 + o2
    total = 0.0
    for row in range(max(0, -o1), n1 - max(0, o1)):
        start = (plane * n1 + row) * n2
        for p in range(start + max(0, -o2), start + n2 - max(0, o2)):
            q = p + shift
            squared = 0.0
            for axis in range(x.shape[1]):
                d = x[p, axis] - x[q, axis]
                squared += d * d
            total += spring_energy(k, rest, math.sqrt(squared))
    return total


def _compile(parallel: bool) -> Callable:
    """`grid_sum` compiled for threads (``parallel``) or for one thread (the same sums)."""
    loop = numba.prange if parallel else range

    @numba.njit(cache=True, parallel=parallel, error_model="numpy")
    def grid_sum(x, shape, offsets, stiffness, rest_lengths):
        """The energy (J) of all springs (see `_plane_sum`), with the ``stiffness`` (N/m)
        and ``rest_lengths`` (m) of each offset (M,); the threads take planes, and the
        sums are added in a fixed order."""
        sums = np.zeros((len(offsets), shape[0]))
        for m in range(len(offsets)):
            for plane in loop(max(0, -offsets[m, 0]), shape[0] - max(0, offsets[m, 0])):
                sums[m, plane] = _plane_sum(x, shape, offsets, stiffness, rest_lengths, m, plane)
        return sums.sum()

    return grid_sum


grid_sum_serial, grid_sum_parallel = _compile(False), _compile(True)
