"""Grid stencils: springs that join every particle of a grid to its neighbours by fixed offsets.

`Body.grid` lays its springs out this way, one block per offset. A spring
kernel that knows it can gather each particle's forces from its neighbours by
offset, with no list of springs (see `msdlab.compiled`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .body import Body


@dataclass(frozen=True)
class GridStencil:
    """Springs that form a regular grid stencil, as `Body.grid` builds them.

    The particles fill a grid of ``shape`` (3,) in C order (2-D grids as
    (1, n0, n1)); spring block m, ``starts[m]`` to ``starts[m + 1] - 1``, joins
    every particle p to the particle at p's grid coordinates plus ``offsets[m]``
    (3,), in the order of `lattice.grid_pair_blocks`. With the same stiffness,
    rest length and dashpot in each block, the forces on a particle can be
    gathered from its neighbours by offset, with no list of springs.
    """

    shape: np.ndarray
    offsets: np.ndarray
    starts: np.ndarray


def grid_stencil(body: Body) -> GridStencil | None:
    """The grid stencil the springs of ``body`` form, or None if they form none.

    Needs ``body.grid_shape`` and springs in blocks of one offset each, every
    block holding all the pairs of its offset in grid order (checked block by
    block, not assumed). Whether the spring values are uniform per block is
    for the caller to check, as they may change at any step.
    """
    shape = body.grid_shape
    if shape is None or math.prod(shape) != body.n_particles or body.n_springs == 0:
        return None
    padded = (1,) * (3 - len(shape)) + tuple(shape)
    index = np.arange(body.n_particles, dtype=np.int64).reshape(padded)
    a, b = body.spring_a, body.spring_b
    offsets, starts = [], [0]
    while starts[-1] < body.n_springs:
        first = starts[-1]
        offset = np.subtract(np.unravel_index(b[first], padded), np.unravel_index(a[first], padded))
        source = tuple(slice(max(0, -o), n - max(0, o)) for o, n in zip(offset, padded))
        expected = index[source].ravel()
        stop = first + len(expected)
        shift = int(offset @ np.array([padded[1] * padded[2], padded[2], 1]))
        if (
            stop > body.n_springs
            or not np.array_equal(a[first:stop], expected)
            or not np.array_equal(b[first:stop], expected + shift)
        ):
            return None
        offsets.append(offset)
        starts.append(stop)
    return GridStencil(np.array(padded), np.array(offsets, dtype=np.int64), np.array(starts))
