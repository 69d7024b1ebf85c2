"""Regular grids of particles, and the lattice: a spring set kept per neighbour offset.

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

from .errors import check_non_negative, check_positive, shown
from .springs import EdgeSprings, SpringValues, read_only

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


def grid_positions(
    shape: Sequence[int], spacing: float, origin: Sequence[float] | None = None
) -> np.ndarray:
    """Positions (prod(shape), dim) of the grid points origin + spacing·(i, j[, k]), C order
    (``spacing`` > 0 in m; ``origin`` default 0), else ValueError saying what works."""
    spacing = check_positive("spacing", spacing, "Grid spacing is in m and must be > 0.")
    origin = np.zeros(len(shape)) if origin is None else np.asarray(origin, dtype=float)
    if origin.shape != (len(shape),):
        raise ValueError(f"origin must have {len(shape)} coordinates, got {origin.tolist()}")
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


def grid_pairs(shape: Sequence[int], offsets: np.ndarray) -> np.ndarray:
    """The blocks of `grid_pair_blocks` in one array (E, 2)."""
    return np.concatenate([np.zeros((0, 2), np.int64), *grid_pair_blocks(shape, offsets)])


@dataclass(frozen=True, eq=False)
class LatticeSprings:
    """A body's springs kept per neighbour offset, with no per-spring arrays.

    The particles fill a grid of ``shape`` in C order. Offset m joins every particle
    to the one at its grid coordinates plus ``offsets[m]`` (M, d), by ``counts[m]``
    springs of stiffness ``stiffness[m]`` (N/m), rest length ``rest_lengths[m]`` (m)
    and dashpot ``damping[m]`` (N·s/m); spring numbers run offset by offset, in the
    order of `grid_pair_blocks`. Make one with `lattice_springs`.
    """

    shape: tuple[int, ...]
    offsets: np.ndarray
    stiffness: np.ndarray
    rest_lengths: np.ndarray
    damping: np.ndarray
    counts: np.ndarray  # springs per offset, Π max(0, n - |o|)

    def __post_init__(self) -> None:
        read_only(self.offsets, self.counts, *self.values())

    @property
    def count(self) -> int:
        """Number of springs E."""
        return int(self.counts.sum())

    def values(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stiffness (N/m), rest lengths (m) and dashpots (N·s/m) per offset, each (M,)."""
        return self.stiffness, self.rest_lengths, self.damping

    def spring(self, index: int) -> SpringValues:
        """Spring ``index``'s particles and values (found from the counts, laid out nowhere)."""
        starts = np.cumsum(self.counts)
        m = int(np.searchsorted(starts, index, side="right"))
        offset = self.offsets[m]
        sources = [n - abs(int(o)) for o, n in zip(offset, self.shape)]
        local = np.unravel_index(index - (starts[m] - self.counts[m]), sources)
        first = np.add(local, np.maximum(0, -offset))
        a, b = (
            np.ravel_multi_index(first, self.shape),
            np.ravel_multi_index(first + offset, self.shape),
        )
        return SpringValues(int(a), int(b), *(float(array[m]) for array in self.values()))

    def edges(self) -> EdgeSprings:
        """The springs as an edge list (E,): laid out now, new arrays each call."""
        pairs = grid_pairs(self.shape, self.offsets)
        values = (np.repeat(array, self.counts) for array in self.values())
        return EdgeSprings(pairs[:, 0].copy(), pairs[:, 1].copy(), *values)

    def joined(self, other: EdgeSprings) -> EdgeSprings:
        """``other``, if this lattice has no springs (a grid built with ``neighbours=()``);
        else ValueError saying how to make an edge list to add springs to."""
        if self.count == 0:
            return other
        raise ValueError(
            "this grid keeps its springs per neighbour offset; to add springs to it, first "
            "make its springs an edge list: body.springs_as_edges()"
        )

    def set_values(self, springs: np.ndarray | None, **values: np.ndarray) -> None:
        """Give all springs (``springs`` None) one new value each of ``values`` (checked, 0-d);
        the values of some springs, or one per spring, need an edge list."""
        if springs is not None or any(np.ndim(value) for value in values.values()):
            raise ValueError(
                "this grid keeps one value per neighbour offset, so its springs change all at "
                "once (body.set_springs(stiffness=50.0)); to give springs values of their own, "
                "first make its springs an edge list: body.springs_as_edges()"
            )
        for name, value in values.items():
            array = getattr(self, name)
            array.flags.writeable = True
            array[...] = value
            array.flags.writeable = False


def lattice_springs(
    shape: tuple[int, ...],
    neighbours: Iterable[int],
    spacing: float | np.ndarray,
    stiffness: float,
    damping: float,
) -> LatticeSprings:
    """The lattice joining each grid point to its ``neighbours`` (squared distances in grid
    units, `neighbour_offsets`), at rest for grid ``spacing`` (m, one or one per axis):
    rest length |o·spacing| for offset o; one ``stiffness`` k >= 0 (N/m) and ``damping``
    c >= 0 (N·s/m) for all."""
    k = check_non_negative("stiffness", stiffness, f"Use k >= 0 in N/m, e.g. {GRID_EXAMPLE}.")
    c = check_non_negative("damping", damping, "Use a dashpot c >= 0 in N·s/m, e.g. damping=0.1.")
    if k.ndim or c.ndim:
        raise ValueError("a grid takes one stiffness and one damping for all its springs")
    offsets = neighbour_offsets(len(shape), neighbours)
    counts = np.array(
        [math.prod(max(0, n - abs(int(o))) for o, n in zip(offset, shape)) for offset in offsets],
        dtype=np.int64,
    )
    per_offset = np.ones(len(offsets))
    rest = np.sqrt(((offsets * np.asarray(spacing, dtype=float)) ** 2).sum(axis=1))
    return LatticeSprings(tuple(shape), offsets, k * per_offset, rest, c * per_offset, counts)
