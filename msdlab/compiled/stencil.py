"""A lattice (`lattice.LatticeSprings`) laid out for the gather loop (`gather`), and that loop's
scratch memory.

The gather walks the particles in C order, each one's springs to the neighbours
ahead of it, three offsets at a time (a triple). Here the offsets are grouped
into triples, the spring values arranged per triple, and the particles whose
neighbour would leave their grid row masked; all of it is a few small arrays,
made again whenever the lattice is edited.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..lattice import LatticeSprings

# Particles a gather block holds (whole grid rows): long inner loops, enough blocks for threads.
GATHER_BLOCK = 4096


class Triples(NamedTuple):
    """The lattice's offsets, each pointing ahead, three at a time; T triples.

    Triple t joins each particle to those at grid offsets (``ahead[t]``, ``along[t, j]``),
    j = 0, 1, 2 (``ahead``: the first two coordinates, ``along``: the last), by springs
    of ``stiffness``, ``rest_lengths``, ``damping`` and ``inverse_rest_squared`` 1/l²
    (T, 3 each); ``masks[t, j]`` is the row of `column_masks` for that neighbour. A
    place with no spring has all values 0 and the all-zero mask, and fills triples
    from the back, so ``masks[t, 1]`` is that mask for a triple of one spring.
    """

    ahead: np.ndarray
    along: np.ndarray
    masks: np.ndarray
    stiffness: np.ndarray
    rest_lengths: np.ndarray
    damping: np.ndarray
    inverse_rest_squared: np.ndarray


class Layout(NamedTuple):
    """A lattice's grid as the gather reads it: ``shape`` (3,) in C order (2-D as
    (1, n0, n1)), the column masks (`column_masks`) and the number of grid ``rows`` a
    block of work holds."""

    shape: np.ndarray
    columns: np.ndarray
    rows: int


class Scratch(NamedTuple):
    """The gather's memory, particle p at column p + ``pad``: ``positions``,
    ``velocities`` and ``forces`` by coordinate (3, N + 2·pad) and each particle's
    largest squared stretch |d|²/l² (N + 2·pad,). The padding stays zero, so a masked
    neighbour past either end is still in memory."""

    positions: np.ndarray
    velocities: np.ndarray
    forces: np.ndarray
    squared: np.ndarray
    pad: int


def padded_shape(lattice: LatticeSprings) -> tuple[np.ndarray, np.ndarray]:
    """The lattice's shape (3,) and offsets (M, 3), 2-D ones as the plane (1, n0, n1)."""
    missing = 3 - len(lattice.shape)
    offsets = np.zeros((len(lattice.offsets), 3), dtype=np.int64)
    offsets[:, missing:] = lattice.offsets
    return np.array((1,) * missing + lattice.shape, dtype=np.int64), offsets


def layout(lattice: LatticeSprings) -> tuple[Layout, Triples]:
    """The gather's layout of ``lattice`` and its `Triples`, with its values as they are now."""
    shape, offsets = padded_shape(lattice)
    groups: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for m, offset in enumerate(offsets.tolist()):
        o0, o1, o2 = offset if tuple(offset) > (0, 0, 0) else [-o for o in offset]
        groups.setdefault((o0, o1), []).append((o2, m))
    ahead, along, members = [], [], []
    for first_two, group in sorted(groups.items()):
        group = sorted(group) + [(0, -1)] * (-len(group) % 3)
        for start in range(0, len(group), 3):
            ahead.append(first_two)
            along.append([o2 for o2, _ in group[start : start + 3]])
            members.append([m for _, m in group[start : start + 3]])
    along_, member = (np.array(rows, np.int64).reshape(-1, 3) for rows in (along, members))
    columns, rows = column_masks(shape, offsets)
    reach = int(np.abs(offsets[:, 2]).max(initial=0))
    masks = np.where(member >= 0, along_ + reach, len(columns) - 1)
    values = [np.where(member >= 0, array[member], 0.0) for array in lattice.values()]
    with np.errstate(divide="ignore"):
        inverse = np.where(member >= 0, 1.0 / values[1] ** 2, 0.0)
    ahead_ = np.array(ahead, np.int64).reshape(-1, 2)
    return Layout(shape, columns, rows), Triples(ahead_, along_, masks, *values, inverse)


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


def scratch(lattice: LatticeSprings, n_particles: int) -> Scratch:
    """Zeroed scratch memory (`Scratch`) for the gather of ``lattice`` on ``n_particles``."""
    pad = 2 * int(np.abs(lattice.offsets[:, -1]).max(initial=0))  # the last axis's reach, twice
    width = n_particles + 2 * pad
    return Scratch(*np.zeros((3, 3, width)), np.zeros(width), pad)


class Plan(NamedTuple):
    """What the gather of ``lattice`` at ``version`` (`Body.version`) on ``particles``
    particles reads: the fields of its `Layout`, `Triples` and `Scratch` in one tuple
    (``arguments``, the gather's), its scratch ``forces`` by coordinate, seen as (N, d),
    and its number of ``springs``."""

    lattice: LatticeSprings | None
    version: int
    particles: int
    arguments: tuple
    forces: np.ndarray
    springs: int


NO_PLAN = Plan(None, -1, -1, (), np.zeros((0, 0)), 0)


def plan(lattice: LatticeSprings, version: int, n_particles: int) -> Plan:
    """The gather's `Plan` for ``lattice``, edited ``version`` times, on ``n_particles``."""
    grid, triples = layout(lattice)
    memory = scratch(lattice, n_particles)
    forces = memory.forces[: len(lattice.shape), memory.pad : memory.pad + n_particles].T
    arguments = (*grid, *triples, *memory)
    return Plan(lattice, version, n_particles, arguments, forces, lattice.count)
