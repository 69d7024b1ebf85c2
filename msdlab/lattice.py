"""Regular grids of particles and the springs between lattice neighbours.

Neighbours are named by their squared distance in grid units, as in the brief:
1 = the axis neighbours (rest length h), 2 = face diagonals (h·√2),
3 = body diagonals (h·√3); 4 = two cells along an axis (bending springs), ...
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Iterator, Sequence

import numpy as np


def neighbour_offsets(dim: int, squared_distances: Iterable[int]) -> np.ndarray:
    """Integer offsets (M, dim) whose squared length is in ``squared_distances``.

    Only one of each pair ±o is returned (the one whose first non-zero entry is
    positive), so every spring is made once. In 3-D, {1, 2, 3} gives 3 + 6 + 4 = 13
    offsets: each particle has 6 + 12 + 8 = 26 neighbours.
    """
    if dim not in (2, 3):
        raise ValueError(f"grids are 2-D or 3-D, got dim = {dim}")
    wanted = sorted({_squared_distance(s) for s in squared_distances})
    if not wanted:
        return np.zeros((0, dim), dtype=np.int64)
    reach = math.isqrt(wanted[-1])
    offsets = [
        offset
        for s in wanted
        for offset in itertools.product(range(-reach, reach + 1), repeat=dim)
        if sum(c * c for c in offset) == s and next(c for c in offset if c != 0) > 0
    ]
    return np.array(offsets, dtype=np.int64).reshape(-1, dim)


def _squared_distance(value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(
            f"neighbours are squared distances in grid units (1, 2, 3, ...), got {value!r}; "
            "use 1 for axis springs, 2 for face diagonals (√2), 3 for body diagonals (√3)"
        )
    return int(value)


def grid_positions(shape: Sequence[int], spacing: float, origin: Sequence[float]) -> np.ndarray:
    """Positions (prod(shape), dim) of the grid points origin + spacing·(i, j[, k]), C order."""
    axes = [np.arange(n, dtype=float) for n in shape]
    coords = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(shape))
    return np.asarray(origin, dtype=float) + spacing * coords


def grid_pair_blocks(shape: Sequence[int], offsets: np.ndarray) -> Iterator[np.ndarray]:
    """For each offset, the particle index pairs (E_o, 2) it joins, one block at a time.

    Particle (i, j, k) has index ``np.ravel_multi_index((i, j, k), shape)``; a pair
    (p, q) has q at p's grid coordinates plus the offset. Border particles get
    only the neighbours that exist, so an offset o makes Π max(0, n - |o|) pairs.
    """
    index = np.arange(math.prod(shape), dtype=np.int64).reshape(shape)
    for offset in offsets:
        source = tuple(slice(max(0, -o), n - max(0, o)) for o, n in zip(offset, shape))
        target = tuple(slice(max(0, o), n - max(0, -o)) for o, n in zip(offset, shape))
        block = np.empty((*index[source].shape, 2), dtype=np.int64)
        block[..., 0], block[..., 1] = index[source], index[target]
        yield block.reshape(-1, 2)


def grid_pair_count(shape: Sequence[int], offsets: np.ndarray) -> int:
    """Number of pairs `grid_pair_blocks` makes, Σ over offsets of Π max(0, n - |o|)."""
    return sum(
        math.prod(max(0, n - abs(int(o))) for o, n in zip(offset, shape)) for offset in offsets
    )


def grid_pairs(shape: Sequence[int], offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Particle index pairs (E, 2) joined by ``offsets``, and each pair's offset index (E,).

    The blocks of `grid_pair_blocks`, one after the other.
    """
    blocks = list(grid_pair_blocks(shape, offsets))
    if not blocks:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    kinds = np.repeat(np.arange(len(blocks)), [len(block) for block in blocks])
    return np.concatenate(blocks), kinds
