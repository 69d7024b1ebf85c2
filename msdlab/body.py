"""Body: particles and springs, stored as arrays (one row per particle / spring)."""

from __future__ import annotations

import math
import operator
from collections.abc import Iterator, Sequence
from typing import Generic, TypeVar

import numpy as np

from .errors import as_vectors, check_non_negative, check_positive
from .lattice import grid_pair_blocks, grid_pair_count, grid_positions, neighbour_offsets
from .particle import Particle
from .spring import Spring

Item = TypeVar("Item", Particle, Spring)


class Body:
    """A mass-spring body in 2-D or 3-D (fixed by the first particle added).

    The state lives in arrays, so the whole body is updated at once:
    ``positions`` (N, d) m, ``velocities`` (N, d) m/s, ``masses`` (N,) kg,
    ``fixed`` (N,) bool; springs in ``spring_a``, ``spring_b`` (E,) particle
    indices, ``stiffness`` (E,) N/m, ``rest_lengths`` (E,) m, ``spring_damping``
    (E,) N·s/m. These are writeable views, valid until the body grows.
    ``particles[i]`` and ``springs[k]`` are objects reading/writing the same rows.
    """

    def __init__(self, dim: int | None = None) -> None:
        if dim not in (None, 2, 3):
            raise ValueError(f"a body is 2-D or 3-D, got dim = {dim!r}")
        self.dim = dim
        self.grid_shape: tuple[int, ...] | None = None
        self.topology_version = 0
        self.parameters_version = 0  # counts accesses that may edit spring values
        self._n = self._e = 0
        self._x = self._v = np.zeros((0, dim or 3))
        self._m = np.zeros(0)
        self._fixed = np.zeros(0, dtype=bool)
        self._a = self._b = np.zeros(0, dtype=np.int64)
        self._k = self._rest = self._c = np.zeros(0)

    # ----------------------------------------------------------------- state views
    @property
    def n_particles(self) -> int:
        return self._n

    @property
    def n_springs(self) -> int:
        return self._e

    def __len__(self) -> int:
        return self._n

    @property
    def positions(self) -> np.ndarray:
        """Positions (N, d) in m."""
        return self._x[: self._n]

    @positions.setter
    def positions(self, value: object) -> None:
        self._x[: self._n] = as_vectors("positions", value, self._dim_or_3(), self._n)

    @property
    def velocities(self) -> np.ndarray:
        """Velocities (N, d) in m/s."""
        return self._v[: self._n]

    @velocities.setter
    def velocities(self, value: object) -> None:
        value = as_vectors("velocities", value, self._dim_or_3(), self._n)
        value[self.fixed] = 0.0
        self._v[: self._n] = value

    @property
    def masses(self) -> np.ndarray:
        """Masses (N,) in kg."""
        return self._m[: self._n]

    @masses.setter
    def masses(self, value: object) -> None:
        self._m[: self._n] = self._checked_masses(value, self._n)

    @property
    def fixed(self) -> np.ndarray:
        """True for pinned particles (N,)."""
        return self._fixed[: self._n]

    @fixed.setter
    def fixed(self, value: object) -> None:
        mask = np.broadcast_to(np.asarray(value, dtype=bool), (self._n,))
        self._fixed[: self._n] = mask
        self.velocities[mask] = 0.0

    @property
    def spring_a(self) -> np.ndarray:
        """First particle of each spring (E,), read-only."""
        return _read_only(self._a[: self._e])

    @property
    def spring_b(self) -> np.ndarray:
        """Second particle of each spring (E,), read-only."""
        return _read_only(self._b[: self._e])

    @property
    def stiffness(self) -> np.ndarray:
        """Spring stiffness k (E,) in N/m."""
        self.parameters_version += 1  # the caller may write to it
        return self._k[: self._e]

    @property
    def rest_lengths(self) -> np.ndarray:
        """Spring rest lengths l (E,) in m."""
        self.parameters_version += 1  # the caller may write to it
        return self._rest[: self._e]

    @property
    def spring_damping(self) -> np.ndarray:
        """Dashpot coefficient c along each spring (E,) in N·s/m."""
        self.parameters_version += 1  # the caller may write to it
        return self._c[: self._e]

    def spring_values(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Stiffness (N/m), rest lengths (m) and dashpots (N·s/m) (E,) to read only.

        Unlike `stiffness`, `rest_lengths` and `spring_damping` this does not
        count as a possible edit in ``parameters_version``.
        """
        return self._k[: self._e], self._rest[: self._e], self._c[: self._e]

    @property
    def particles(self) -> _Items[Particle]:
        """``particles[i]`` reads/writes particle i's rows of the arrays."""
        return _Items(self, Particle, self._n)

    @property
    def springs(self) -> _Items[Spring]:
        """``springs[k]`` reads/writes spring k's rows of the arrays."""
        return _Items(self, Spring, self._e)

    # ----------------------------------------------------------------- building
    def add_particle(self, particle: Particle) -> int:
        """Add ``particle`` and return its index; the object then reads/writes this body."""
        if not isinstance(particle, Particle):
            raise TypeError(f"add_particle takes a msdlab.Particle, got {type(particle).__name__}")
        if particle.is_bound:
            raise ValueError(
                "this particle already belongs to a body; make a new Particle for each body"
            )
        own = particle.own_values
        (index,) = self.add_particles(
            own["position"][None], own["velocity"][None], own["mass"], own["fixed"]
        )
        particle.bind(self, int(index))
        return int(index)

    def add_particles(
        self,
        positions: object,
        velocities: object = None,
        masses: object = 1.0,
        fixed: object = False,
    ) -> np.ndarray:
        """Add many particles at once (arrays or broadcastable values); return their indices."""
        positions = np.array(positions, dtype=float)
        dim = positions.shape[-1] if positions.ndim == 2 else None
        if dim not in (2, 3):
            raise ValueError(
                f"positions must have shape (N, 2) or (N, 3), got shape {positions.shape}"
            )
        if self.dim is not None and dim != self.dim:
            raise ValueError(
                f"this body is {self.dim}-D but the new particle has {dim} coordinates; "
                "do not mix 2-D and 3-D particles in one body"
            )
        count = len(positions)
        positions = as_vectors("positions", positions, dim, count)
        velocities = (
            np.zeros_like(positions)
            if velocities is None
            else as_vectors("velocities", velocities, dim, count)
        )
        masses = self._checked_masses(masses, count)
        fixed = np.broadcast_to(np.asarray(fixed, dtype=bool), (count,))
        if self.dim is None:
            self.dim = dim
            self._x = self._v = np.zeros((0, dim))
        start = self._n
        self._reserve_particles(start + count)
        self._x[start : start + count] = positions
        self._v[start : start + count] = np.where(fixed[:, None], 0.0, velocities)
        self._m[start : start + count] = masses
        self._fixed[start : start + count] = fixed
        self._n += count
        self.topology_version += 1
        return np.arange(start, start + count)

    def add_spring(self, spring: Spring) -> int:
        """Add ``spring`` and return its index; the object then reads/writes this body."""
        if not isinstance(spring, Spring):
            raise TypeError(f"add_spring takes a msdlab.Spring, got {type(spring).__name__}")
        if spring.is_bound:
            raise ValueError("this spring already belongs to a body; make a new Spring")
        own = spring.own_values
        (index,) = self.add_springs(
            [[own["a"], own["b"]]],
            own["stiffness"],
            None if own["rest_length"] is None else [own["rest_length"]],
            own["damping"],
        )
        spring.bind(self, int(index))
        return int(index)

    def add_springs(
        self,
        pairs: object,
        stiffness: object = 1.0,
        rest_lengths: object = None,
        damping: object = 0.0,
    ) -> np.ndarray:
        """Add springs between index pairs (E, 2); rest lengths default to current distances."""
        pairs = np.asarray(pairs)
        if pairs.size == 0:  # also () and [], which numpy makes float
            pairs = pairs.reshape(0, 2).astype(np.int64)
        if pairs.ndim != 2 or pairs.shape[1] != 2:
            raise ValueError(f"spring pairs must have shape (E, 2), got shape {pairs.shape}")
        if not np.issubdtype(pairs.dtype, np.integer):
            raise TypeError(f"spring ends must be integer particle indices, got {pairs.dtype}")
        pairs = pairs.astype(np.int64, copy=False)
        bad = np.flatnonzero(np.any((pairs < 0) | (pairs >= self._n), axis=1))
        if len(bad):
            a, b = pairs[bad[0]]
            raise ValueError(
                f"spring {bad[0]} joins particles {a} and {b}, but the body has {self._n} "
                f"particles (indices 0 to {self._n - 1}); add the particles first"
            )
        same = np.flatnonzero(pairs[:, 0] == pairs[:, 1])
        if len(same):
            raise ValueError(
                f"spring {same[0]} joins particle {pairs[same[0], 0]} to itself; "
                "a spring needs two different particles"
            )
        count = len(pairs)
        stiffness = np.broadcast_to(np.asarray(stiffness, dtype=float), (count,))
        damping = np.broadcast_to(np.asarray(damping, dtype=float), (count,))
        check_non_negative("stiffness", stiffness, "Use k >= 0 (N/m).")
        check_non_negative("damping", damping, "Use a dashpot coefficient c >= 0 (N·s/m).")
        if rest_lengths is None:
            rest_lengths = np.linalg.norm(
                self.positions[pairs[:, 0]] - self.positions[pairs[:, 1]], axis=1
            )
            zero = np.flatnonzero(rest_lengths == 0)
            if len(zero):
                a, b = pairs[zero[0]]
                raise ValueError(
                    f"zero-length spring: particles {a} and {b} are at the same position "
                    f"{self.positions[a].tolist()}; move them apart or give rest_length > 0"
                )
        rest_lengths = np.broadcast_to(np.asarray(rest_lengths, dtype=float), (count,))
        bad = np.flatnonzero(~np.isfinite(rest_lengths) | (rest_lengths <= 0))
        if len(bad):
            raise ValueError(
                f"spring {bad[0]} has rest length {rest_lengths[bad[0]]!r}; "
                "rest lengths must be > 0 (m)"
            )
        start = self._e
        self._reserve_springs(start + count)
        self._a[start : start + count] = pairs[:, 0]
        self._b[start : start + count] = pairs[:, 1]
        self._k[start : start + count] = stiffness
        self._rest[start : start + count] = rest_lengths
        self._c[start : start + count] = damping
        self._e += count
        self.topology_version += 1
        return np.arange(start, start + count)

    @classmethod
    def from_arrays(
        cls,
        positions: object,
        springs: object = (),
        *,
        velocities: object = None,
        masses: object = 1.0,
        fixed: object = False,
        stiffness: object = 1.0,
        rest_lengths: object = None,
        damping: object = 0.0,
    ) -> Body:
        """A body from arrays: positions (N, d), spring index pairs (E, 2) and their values."""
        body = cls()
        body.add_particles(positions, velocities, masses, fixed)
        body.add_springs(springs, stiffness, rest_lengths, damping)
        return body

    @classmethod
    def grid(
        cls,
        shape: Sequence[int],
        spacing: float = 1.0,
        stiffness: float = 1.0,
        neighbours: Sequence[int] = (1,),
        origin: Sequence[float] | None = None,
        mass: float = 1.0,
        damping: float = 0.0,
    ) -> Body:
        """A 2-D or 3-D grid of particles ``origin + spacing·(i, j[, k])``, C order.

        ``neighbours`` are squared distances in grid units: 1 makes axis springs
        (rest length = spacing), 2 face diagonals (√2·spacing), 3 body diagonals
        (√3·spacing). The grid is at rest: every spring starts at its rest length.
        """
        shape = tuple(operator.index(n) for n in shape)
        if len(shape) not in (2, 3) or min(shape) < 1:
            raise ValueError(f"grid shape must be 2 or 3 positive sizes, got {shape}")
        spacing = check_positive("spacing", spacing, "Grid spacing is in m and must be > 0.")
        origin = np.zeros(len(shape)) if origin is None else np.asarray(origin, dtype=float)
        if origin.shape != (len(shape),):
            raise ValueError(f"origin must have {len(shape)} coordinates, got {origin.tolist()}")
        offsets = neighbour_offsets(len(shape), neighbours)
        body = cls()
        body.add_particles(grid_positions(shape, spacing, origin), masses=mass)
        body._reserve_springs(grid_pair_count(shape, offsets))  # exactly: no regrowth
        for offset, pairs in zip(offsets, grid_pair_blocks(shape, offsets)):
            rest = spacing * math.sqrt(float(offset @ offset))
            body.add_springs(pairs, stiffness, rest, damping)
        body.grid_shape = shape
        return body

    # ----------------------------------------------------------------- helpers
    def copy(self) -> Body:
        """An independent copy of the body (state and springs)."""
        body = (
            Body.from_arrays(
                self.positions,
                np.stack([self.spring_a, self.spring_b], axis=1),
                velocities=self.velocities,
                masses=self.masses,
                fixed=self.fixed,
                stiffness=self.stiffness,
                rest_lengths=self.rest_lengths,
                damping=self.spring_damping,
            )
            if self._n
            else Body(self.dim)
        )
        body.grid_shape = self.grid_shape
        return body

    def center_of_mass(self) -> np.ndarray:
        """Mass-weighted mean position (m)."""
        return self.masses @ self.positions / self.masses.sum()

    def rotate(self, rotation: np.ndarray, about: Sequence[float] | None = None) -> None:
        """Rotate positions and velocities by a (d, d) rotation matrix about a point.

        ``about`` defaults to the centre of mass. See `rotation_matrix`.
        """
        rotation = np.asarray(rotation, dtype=float)
        if rotation.shape != (self.dim, self.dim) or not np.allclose(
            rotation @ rotation.T, np.eye(self.dim), atol=1e-9
        ):
            raise ValueError(f"rotation must be an orthogonal ({self.dim}, {self.dim}) matrix")
        centre = self.center_of_mass() if about is None else np.asarray(about, dtype=float)
        self.positions[:] = (self.positions - centre) @ rotation.T + centre
        self.velocities[:] = self.velocities @ rotation.T

    def incident_springs(self) -> tuple[np.ndarray, np.ndarray]:
        """CSR lists of the springs touching each particle: ``springs[start[i]:start[i+1]]``."""
        cached = getattr(self, "_incidence", None)
        if cached is not None and cached[0] == self.topology_version:
            return cached[1], cached[2]
        ends = np.concatenate([self.spring_a, self.spring_b])
        order = np.argsort(ends, kind="stable")
        start = np.zeros(self._n + 1, dtype=np.int64)
        np.cumsum(np.bincount(ends, minlength=self._n), out=start[1:])
        springs = order % max(self._e, 1)
        self._incidence = (self.topology_version, start, springs)
        return start, springs

    def springs_touching(self, particles: np.ndarray) -> np.ndarray:
        """Indices of the springs with an end in ``particles`` (sorted, unique)."""
        start, springs = self.incident_springs()
        counts = start[particles + 1] - start[particles]
        first = np.repeat(start[particles] - (np.cumsum(counts) - counts), counts)
        found = np.sort(springs[first + np.arange(counts.sum())])
        return found[np.concatenate(([True], found[1:] != found[:-1]))] if len(found) else found

    def _dim_or_3(self) -> int:
        return self.dim or 3

    @staticmethod
    def _checked_masses(value: object, count: int) -> np.ndarray:
        masses = np.broadcast_to(np.asarray(value, dtype=float), (count,))
        bad = np.flatnonzero(~np.isfinite(masses) | (masses <= 0))
        if len(bad):
            raise ValueError(
                f"mass of particle {bad[0]} is {masses[bad[0]]!r}; every mass must be > 0 (kg). "
                "To pin a particle use fixed=True instead of a zero mass"
            )
        return masses

    def _reserve_particles(self, needed: int) -> None:
        if needed > len(self._m):
            capacity = max(needed, 2 * len(self._m), 8)
            self._x = _grown(self._x, capacity)
            self._v = _grown(self._v, capacity)
            self._m = _grown(self._m, capacity)
            self._fixed = _grown(self._fixed, capacity)

    def _reserve_springs(self, needed: int) -> None:
        if needed > len(self._k):
            capacity = max(needed, 2 * len(self._k), 8)
            self._a, self._b = _grown(self._a, capacity), _grown(self._b, capacity)
            self._k, self._rest = _grown(self._k, capacity), _grown(self._rest, capacity)
            self._c = _grown(self._c, capacity)

    def __repr__(self) -> str:
        kind = f"{self.dim}-D" if self.dim else "empty"
        grid = f", grid {self.grid_shape}" if self.grid_shape else ""
        return f"<Body {kind}: {self._n} particles, {self._e} springs{grid}>"


def rotation_matrix(angle_degrees: float, axis: Sequence[float] | None = None) -> np.ndarray:
    """Right-handed rotation by ``angle_degrees``: 2×2 in 2-D (no axis), 3×3 about ``axis``."""
    angle = math.radians(angle_degrees)
    c, s = math.cos(angle), math.sin(angle)
    if axis is None:
        return np.array([[c, -s], [s, c]])
    axis = np.asarray(axis, dtype=float)
    norm = np.linalg.norm(axis)
    if axis.shape != (3,) or not np.isfinite(norm) or norm == 0:
        raise ValueError(f"rotation axis must be a non-zero 3-vector, got {axis.tolist()}")
    x, y, z = axis / norm
    cross = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return c * np.eye(3) + s * cross + (1 - c) * np.outer([x, y, z], [x, y, z])


class _Items(Sequence, Generic[Item]):
    """``body.particles`` / ``body.springs``: objects bound to rows of the body's arrays."""

    def __init__(self, body: Body, kind: type[Item], count: int) -> None:
        self._body, self._kind, self._count = body, kind, count

    def __len__(self) -> int:
        return self._count

    def __getitem__(self, index: int) -> Item:  # type: ignore[override]
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(self._count))]  # type: ignore[return-value]
        position = operator.index(index)
        if not -self._count <= position < self._count:
            raise IndexError(
                f"{self._kind.__name__.lower()} {index} does not exist: the body has "
                f"{self._count} (indices 0 to {self._count - 1})"
            )
        return self._kind.row(self._body, position % self._count)

    def __iter__(self) -> Iterator[Item]:
        return (self[i] for i in range(self._count))


def _grown(array: np.ndarray, capacity: int) -> np.ndarray:
    grown = np.zeros((capacity, *array.shape[1:]), dtype=array.dtype)
    grown[: len(array)] = array
    return grown


def _read_only(view: np.ndarray) -> np.ndarray:
    view.flags.writeable = False
    return view
