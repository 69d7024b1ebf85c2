"""Regular grids of particles and the springs between lattice neighbours.

Neighbours are named by their squared distance in grid units, as in the brief:
1 = the axis neighbours (rest length h), 2 = face diagonals (h·√2),
3 = body diagonals (h·√3); 4 = two cells along an axis (bending springs), ...
"""

from __future__ import annotations

import itertools
import math
import operator
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from .errors import shown

GRID_EXAMPLE = "Body.grid((4, 4, 4), spacing=0.1, stiffness=100.0)"


def grid_shape(shape: object) -> tuple[int, ...]:
    """``shape`` as a tuple of 2 or 3 positive sizes (particles per axis), else an error
    saying what was given and what works."""
    example = f"give one size per axis, e.g. {GRID_EXAMPLE} for a 4×4×4 cube"
    try:
        sizes = tuple(operator.index(n) for n in shape)  # type: ignore[attr-defined]
    except TypeError:
        raise TypeError(f"grid shape must be 2 or 3 sizes, got {shown(shape)}; {example}") from None
    if len(sizes) not in (2, 3) or min(sizes) < 1:
        raise ValueError(f"grid shape must be 2 or 3 sizes >= 1, got {shown(shape)}; {example}")
    return sizes


def neighbour_offsets(dim: int, squared_distances: Iterable[int]) -> np.ndarray:
    """Integer offsets (M, dim) whose squared length is in ``squared_distances``.

    One of each pair ±o (the one whose first non-zero entry is positive), so every
    spring is made once: in 3-D, {1, 2, 3} gives 3 + 6 + 4 = 13 of the 26 neighbours.
    """
    if dim not in (2, 3):
        raise ValueError(f"grids are 2-D or 3-D, got dim = {dim}")
    wanted = set()
    for s in squared_distances:
        if isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 1:
            raise ValueError(
                f"neighbours are squared distances in grid units (1, 2, 3, ...), got {s!r}; "
                "use 1 for axis springs, 2 for face diagonals (√2), 3 for body diagonals (√3)"
            )
        wanted.add(int(s))
    reach = math.isqrt(max(wanted, default=0))
    offsets = [
        o
        for o in itertools.product(range(-reach, reach + 1), repeat=dim)
        if sum(c * c for c in o) in wanted and next((c for c in o if c), 0) > 0
    ]
    offsets.sort(key=lambda o: sum(c * c for c in o))  # stable: nearest first
    return np.array(offsets, dtype=np.int64).reshape(-1, dim)


def grid_positions(shape: Sequence[int], spacing: float, origin: Sequence[float]) -> np.ndarray:
    """Positions (prod(shape), dim) of the grid points origin + spacing·(i, j[, k]), C order."""
    points = np.empty((*shape, len(shape)))
    for axis, n in enumerate(shape):
        points[..., axis] = np.arange(n).reshape([n if a == axis else 1 for a in range(len(shape))])
    points *= spacing
    points += origin
    return points.reshape(-1, len(shape))


def grid_pair_blocks(shape: Sequence[int], offsets: np.ndarray) -> Iterator[np.ndarray]:
    """For each offset o, the particle index pairs (E_o, 2) it joins.

    Particle (i, j, k) has index ``np.ravel_multi_index((i, j, k), shape)``; in a pair
    (p, q), q sits at p's grid coordinates plus o. Border particles get only the
    neighbours that exist, so o makes Π max(0, n - |o|) pairs.
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
    return sum(math.prod(max(0, n - abs(int(o))) for o, n in zip(off, shape)) for off in offsets)


def grid_pairs(shape: Sequence[int], offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The blocks of `grid_pair_blocks` in one array (E, 2), and each pair's offset index (E,)."""
    blocks = list(grid_pair_blocks(shape, offsets))
    kinds = np.repeat(np.arange(len(blocks)), [len(block) for block in blocks])
    return np.concatenate(blocks or [np.zeros((0, 2), np.int64)]), kinds.astype(np.int64)


@dataclass(frozen=True)
class GridSprings:
    """The springs of a grid stored per neighbour offset, with no per-spring arrays.

    Offset m joins every particle to the one at its grid coordinates plus
    ``offsets[m]`` (M, d), by springs of rest length ``rest_lengths[m]`` (m),
    ``stiffness`` k (N/m) and dashpot ``damping`` c (N·s/m), in the order of
    `grid_pair_blocks`: `Body.grid` keeps its springs this way until their arrays
    are first read.
    """

    shape: tuple[int, ...]
    offsets: np.ndarray
    rest_lengths: np.ndarray
    stiffness: float
    damping: float

    @property
    def count(self) -> int:
        """Number of springs, Σ over offsets of Π max(0, n - |o|)."""
        return grid_pair_count(self.shape, self.offsets)

    def with_values(
        self,
        stiffness: float | None = None,
        rest_lengths: float | None = None,
        spring_damping: float | None = None,
    ) -> GridSprings:
        """These springs with one new stiffness (N/m), rest length (m) or dashpot (N·s/m)
        for all (None keeps a value)."""
        rest = (
            self.rest_lengths
            if rest_lengths is None
            else np.full_like(self.rest_lengths, rest_lengths)
        )
        return GridSprings(
            self.shape,
            self.offsets,
            rest,
            self.stiffness if stiffness is None else stiffness,
            self.damping if spring_damping is None else spring_damping,
        )

    def values(self) -> np.ndarray:
        """Stiffness (N/m), rest length (m) and dashpot (N·s/m) of each offset (3, M)."""
        uniform = np.ones(len(self.offsets))
        return np.stack([self.stiffness * uniform, self.rest_lengths, self.damping * uniform])
