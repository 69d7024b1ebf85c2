"""Grid stencils: springs that join every particle of a grid to its neighbours by fixed offsets.

`Body.grid` lays its springs out this way, one block per offset. A spring
kernel that knows it can gather each particle's forces from its neighbours by
offset, with no list of springs (see `gather`). Here the stencil is found,
its values checked uniform per offset, and laid out as the gather reads it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from ..body import Body
from ..lattice import grid_pair_count

# Particles a gather block holds (whole grid rows): long inner loops, enough blocks for threads.
GATHER_BLOCK = 4096


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

    A grid that keeps its springs per offset (`Body.grid_springs`) forms one
    by construction. Otherwise it needs ``body.grid_shape`` and springs in
    blocks of one offset each, every block holding all the pairs of its offset
    in grid order (checked block by block, not assumed). Whether the spring
    values are uniform per block is for the caller to check, as they may
    change at any step.
    """
    grid = body.grid_springs
    shape = body.grid_shape if grid is None else grid.shape
    if shape is None or math.prod(shape) != body.n_particles or body.n_springs == 0:
        return None
    padded = (1,) * (3 - len(shape)) + tuple(shape)
    if grid is not None:
        offsets = np.zeros((len(grid.offsets), 3), dtype=np.int64)
        offsets[:, 3 - len(shape) :] = grid.offsets
        counts = [grid_pair_count(shape, offset[None]) for offset in grid.offsets]
        return GridStencil(np.array(padded), offsets, np.cumsum([0, *counts]))
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


def stencil_triples(offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The stencil's offsets, each pointing ahead (o or -o, whichever is later in C order),
    grouped by their first two coordinates, three at a time.

    Returns (triples, members, o2s): triple t joins each particle to those at
    (``triples[t]``, ``o2s[t, j]``), j = 0, 1, 2, by the springs of offset
    block ``members[t, j]``; -1 marks an empty place (no spring).
    """
    groups: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for m, offset in enumerate(offsets.tolist()):
        o0, o1, o2 = offset if tuple(offset) > (0, 0, 0) else [-o for o in offset]
        groups.setdefault((o0, o1), []).append((o2, m))
    triples, members, o2s = [], [], []
    for (o0, o1), group in sorted(groups.items()):
        group.sort()
        group += [(0, -1)] * (-len(group) % 3)
        for first in range(0, len(group), 3):
            triples.append((o0, o1))
            o2s.append([o2 for o2, _ in group[first : first + 3]])
            members.append([m for _, m in group[first : first + 3]])
    return (
        np.array(triples, dtype=np.int64).reshape(-1, 2),
        np.array(members, dtype=np.int64).reshape(-1, 3),
        np.array(o2s, dtype=np.int64).reshape(-1, 3),
    )


def column_masks(shape: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, int]:
    """Masks of the particles that have a neighbour ``o_2`` columns along their grid row.

    Returns (masks, rows): ``masks[r + o_2]`` (rows · n_2,) is 1 where column
    c + o_2 exists, for a block of ``rows`` rows of the grid, long enough
    (about ``GATHER_BLOCK`` particles) for the loops over a block to cost
    little more than their arithmetic; the last mask, all 0, is for no spring.
    """
    n1, n2 = int(shape[1]), int(shape[2])
    rows = max(1, min(n1, GATHER_BLOCK // n2))
    reach = int(np.abs(offsets[:, 2]).max(initial=0))
    column = np.arange(n2)
    masks = [np.tile((column + o >= 0) & (column + o < n2), rows) for o in range(-reach, reach + 1)]
    return np.array([*masks, np.zeros(rows * n2, dtype=bool)], dtype=float), rows


def triple_values(values: np.ndarray, members: np.ndarray) -> np.ndarray:
    """Stiffness, rest length, dashpot and 1/rest² (T, 3, 4) of the springs of each triple
    (`stencil_triples`), from the values (3, M) of each offset block; 0 for no spring."""
    k, rest, c = values[:, members]
    with np.errstate(divide="ignore"):
        table = np.stack([k, rest, c, 1.0 / rest**2], axis=-1)
    table[members < 0] = 0.0
    return table


@numba.njit(cache=True)
def uniform_blocks(k, rest, c, starts, values):
    """True if every spring block has one stiffness, rest length and dashpot; they go to
    ``values`` (3, M). Stops at the first spring that differs from its block's first."""
    for m in range(len(starts) - 1):
        first = starts[m]
        values[0, m], values[1, m], values[2, m] = k[first], rest[first], c[first]
        same = True
        for s in range(first, starts[m + 1]):
            same &= (k[s] == k[first]) & (rest[s] == rest[first]) & (c[s] == c[first])
        if not same:
            return False
    return True
