"""A body's springs as an edge list: each spring's two particles and its three values.

A body holds one spring set, of one of two kinds: this edge list, or a lattice
(`lattice.LatticeSprings`, values per neighbour offset). Both answer `count`,
`spring` (one spring's values) and `edges` (the set as an edge list); the
arrays are read-only, and `set_values` is the one way to change them.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any, NamedTuple

import numpy as np

from .errors import check_non_negative

HINTS = {  # each spring value, and what a bad one is told
    "stiffness": "Use k >= 0 (N/m).",
    "rest_lengths": "A spring needs a rest length > 0 (m).",
    "damping": "Use a dashpot coefficient c >= 0 (N·s/m).",
}
LABELS = {"stiffness": "stiffness", "rest_lengths": "rest length", "damping": "damping"}


class SpringValues(NamedTuple):
    """One spring: its particles a, b, stiffness (N/m), rest length (m) and dashpot (N·s/m)."""

    a: int
    b: int
    stiffness: float
    rest_lengths: float
    damping: float


def checked_value(name: str, values: object, count: int) -> np.ndarray:
    """Spring value ``name`` ("stiffness", "rest_lengths" or "damping") for ``count``
    springs: one number (0-d) or one per spring (count,), finite, rest lengths > 0 and
    the others >= 0; else ValueError saying what was given and what works."""
    if name not in HINTS:
        raise TypeError(f"the spring values are {', '.join(HINTS)}, not {name!r}")
    array = check_non_negative(LABELS[name], values, HINTS[name], zero=name != "rest_lengths")
    if array.ndim and array.shape != (count,):
        raise ValueError(
            f"{LABELS[name]} needs one value or one per spring ({count}), got {array.shape}"
        )
    return array


def checked_pairs(pairs: object, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Spring ends a, b (int64) from index pairs (E, 2) of a body of ``n`` particles."""
    pairs = np.asarray(pairs)
    if pairs.size == 0:  # also () and [], which numpy makes float
        pairs = pairs.reshape(0, 2).astype(np.int64)
    if pairs.ndim != 2 or pairs.shape[1] != 2:
        raise ValueError(f"spring pairs must have shape (E, 2), got shape {pairs.shape}")
    if not np.issubdtype(pairs.dtype, np.integer):
        raise TypeError(f"spring ends must be integer particle indices, got {pairs.dtype}")
    if len(pairs) and (pairs.min() < 0 or pairs.max() >= n):
        bad = np.flatnonzero(((pairs < 0) | (pairs >= n)).any(axis=1))[0]
        raise ValueError(
            f"spring {bad} joins particles {pairs[bad, 0]} and {pairs[bad, 1]}, but the body "
            f"has {n} particles (indices 0 to {n - 1}); add the particles first"
        )
    a, b = pairs[:, 0].astype(np.int64), pairs[:, 1].astype(np.int64)
    if (a == b).any():
        same = np.flatnonzero(a == b)[0]
        raise ValueError(
            f"spring {same} joins particle {a[same]} to itself; "
            "a spring needs two different particles"
        )
    return a, b


def distances(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|x_a - x_b| (m) as rest lengths, else ValueError at the first zero one."""
    lengths = np.linalg.norm(x[a] - x[b], axis=1)
    if len(lengths) and lengths.min() == 0:
        zero = np.flatnonzero(lengths == 0)[0]
        raise ValueError(
            f"zero-length spring: particles {a[zero]} and {b[zero]} are at the same "
            f"position {x[a[zero]].tolist()}; move them apart or give rest_length > 0"
        )
    return lengths


def edge_springs(
    positions: np.ndarray, pairs: object, stiffness: object, rest_lengths: object, damping: object
) -> EdgeSprings:
    """Springs between index pairs (E, 2) of particles at ``positions`` (N, d), values one
    per spring or one for all (checked once); rest lengths None: the current distances."""
    a, b = checked_pairs(pairs, len(positions))
    rest_lengths = distances(positions, a, b) if rest_lengths is None else rest_lengths
    given = {"stiffness": stiffness, "rest_lengths": rest_lengths, "damping": damping}
    values = (checked_value(name, value, len(a)) for name, value in given.items())
    return EdgeSprings(a, b, *(np.broadcast_to(value, len(a)).copy() for value in values))


def incidence(edges: EdgeSprings, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """CSR lists of the springs touching each of ``n`` particles and of the particles at
    their other ends, (start, springs, partners): particle i's are
    ``springs[start[i]:start[i+1]]`` and ``partners[start[i]:start[i+1]]``."""
    ends, others = np.concatenate([edges.a, edges.b]), np.concatenate([edges.b, edges.a])
    start = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(ends, minlength=n), out=start[1:])
    order = np.argsort(ends, kind="stable")
    return start, order % max(edges.count, 1), others[order]


def touching(start: np.ndarray, listed: np.ndarray, particles: np.ndarray) -> np.ndarray:
    """The entries (sorted, unique) of ``particles``' CSR lists ``listed`` (the springs or the
    partners of `incidence`)."""
    if len(particles) == 1:  # one slice (a wall's bounce asks for one particle at a time)
        return np.unique(listed[start[particles[0]] : start[particles[0] + 1]])
    counts = start[particles + 1] - start[particles]
    first = np.repeat(start[particles] - (np.cumsum(counts) - counts), counts)
    return np.unique(listed[first + np.arange(counts.sum())])


def read_only(*arrays: np.ndarray) -> None:
    """Make ``arrays`` read-only: a spring set's values change through `set_values` only."""
    for array in arrays:
        array.flags.writeable = False


def copied(springs: Any) -> Any:
    """An independent copy of a spring set of either kind: its arrays copied."""
    arrays = (getattr(springs, field.name) for field in fields(springs))
    return replace(
        springs,
        **{
            field.name: array.copy()
            for field, array in zip(fields(springs), arrays)
            if isinstance(array, np.ndarray)
        },
    )


@dataclass(frozen=True, eq=False)
class EdgeSprings:
    """Springs as an edge list (E,): spring s joins particles ``a[s]`` and ``b[s]`` with
    stiffness ``stiffness[s]`` (N/m), rest length ``rest_lengths[s]`` (m) and dashpot
    ``damping[s]`` (N·s/m). The arrays are read-only; `set_values` edits them."""

    a: np.ndarray
    b: np.ndarray
    stiffness: np.ndarray
    rest_lengths: np.ndarray
    damping: np.ndarray

    def __post_init__(self) -> None:
        read_only(self.a, self.b, *self.values())

    @classmethod
    def empty(cls) -> EdgeSprings:
        """No springs."""
        return cls(np.zeros(0, np.int64), np.zeros(0, np.int64), *np.zeros((3, 0)))

    @property
    def count(self) -> int:
        """Number of springs E."""
        return len(self.a)

    def values(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stiffness (N/m), rest lengths (m) and dashpots (N·s/m), each (E,)."""
        return self.stiffness, self.rest_lengths, self.damping

    def spring(self, index: int) -> SpringValues:
        """Spring ``index``'s particles and values."""
        return SpringValues(*(array[index].item() for array in (self.a, self.b, *self.values())))

    def edges(self) -> EdgeSprings:
        """The springs as an edge list: these."""
        return self

    def joined(self, other: EdgeSprings) -> EdgeSprings:
        """These springs, then ``other``'s, as one edge list (new arrays)."""
        return EdgeSprings(*(np.concatenate(pair) for pair in zip(self.arrays(), other.arrays())))

    def arrays(self) -> tuple[np.ndarray, ...]:
        """a, b, stiffness, rest lengths and dashpots, in that order."""
        return self.a, self.b, *self.values()

    def set_values(self, springs: np.ndarray | None, **values: np.ndarray) -> None:
        """Write checked ``values`` (`checked_value`) into the springs ``springs`` (indices;
        None: all)."""
        for name, value in values.items():
            array = getattr(self, name)
            array.flags.writeable = True
            array[slice(None) if springs is None else springs] = value
            array.flags.writeable = False
