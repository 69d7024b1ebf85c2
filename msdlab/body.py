"""Body: particles and springs, stored as arrays (one row per particle / spring)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from .bound import Rows
from .errors import as_vectors, check_non_negative, check_positive, shown
from .lattice import (
    GRID_EXAMPLE,
    GridSprings,
    grid_pair_blocks,
    grid_positions,
    grid_shape,
    neighbour_offsets,
)
from .particle import Particle
from .spring import Spring

MASS_HINT = "To pin a particle use fixed=True instead of a zero mass."
VALUE_HINTS = {  # the spring values and what a bad one is told
    "stiffness": "Use k >= 0 (N/m).",
    "rest_lengths": "It is in m.",
    "spring_damping": "Use a dashpot coefficient c >= 0 (N·s/m).",
}
SPRING_ARRAYS = ("spring_a", "spring_b", *VALUE_HINTS)


def _per_row(name: str, values: object, count: int, hint: str, zero: bool = True) -> np.ndarray:
    """``values`` checked finite and >= 0 (> 0 unless ``zero``), as ``count`` floats."""
    array = check_non_negative(name, values, hint, zero=zero)
    if array.ndim and array.shape != (count,):
        raise ValueError(f"{name} needs one value or one per row ({count}), got {array.shape}")
    return np.broadcast_to(array, (count,)).copy()


def _pin(body: Body, mask: object) -> None:
    body.fixed[...] = mask
    body.velocities[body.fixed] = 0.0  # pinned particles stop


def _read_only(name: str) -> Callable[[Body, object], None]:
    def refuse(body: Body, value: object) -> None:
        raise AttributeError(f"body.{name} is read-only; add springs with body.add_springs(...)")

    return refuse


# `body.<name> = value`: a whole array, checked and written into the body's arrays
_WHOLE: dict[str, Callable[[Body, object], None]] = {
    "positions": lambda body, x: body.positions.__setitem__(
        ..., as_vectors("positions", x, body.dim or 3, len(body))
    ),
    "velocities": lambda body, v: body.velocities.__setitem__(
        ...,
        np.where(body.fixed[:, None], 0.0, as_vectors("velocities", v, body.dim or 3, len(body))),
    ),
    "masses": lambda body, m: body.masses.__setitem__(
        ..., _per_row("mass", m, len(body), MASS_HINT, zero=False)
    ),
    "fixed": _pin,
    "stiffness": lambda body, k: body.set_springs(stiffness=k),
    "rest_lengths": lambda body, rest: body.set_springs(rest_lengths=rest),
    "spring_damping": lambda body, c: body.set_springs(spring_damping=c),
    **{name: _read_only(name) for name in ("spring_a", "spring_b", "spring_values")},
}


class Body:
    """A mass-spring body in 2-D or 3-D (fixed by the first particle added).

    The state is four arrays, read and written in place: ``positions`` (N, d) in m,
    ``velocities`` (N, d) in m/s, ``masses`` (N,) in kg and ``fixed`` (N,). The springs
    are read-only arrays (E,): ``spring_a``, ``spring_b``, ``stiffness`` (N/m),
    ``rest_lengths`` (m), ``spring_damping`` (N·s/m); they change only through
    `add_springs`, `set_springs` (or assigning a whole array), each of which adds one
    to ``version``. A grid (`Body.grid`) keeps its springs per offset (`grid_springs`)
    until `lay_out_springs` writes them out; ``particles[i]`` and ``springs[k]`` are
    objects reading and writing one row.
    """

    def __init__(self, dim: int | None = None) -> None:
        if dim not in (None, 2, 3):
            raise ValueError(f"a body is 2-D or 3-D, got dim = {shown(dim)}")
        self.dim = dim
        self.grid_shape: tuple[int, ...] | None = None
        self.version = 0  # grows whenever the springs change: added or edited
        self.grid_springs: GridSprings | None = None  # `Body.grid`'s springs, until laid out
        self._incidence: tuple[int, np.ndarray, np.ndarray] | None = None
        self._new_state: tuple[np.ndarray, ...] = ()  # see `new_state`
        width = dim or 3
        self._keep(positions=np.zeros((0, width)), velocities=np.zeros((0, width)))
        self._keep(masses=np.zeros(0), fixed=np.zeros(0, bool))
        self._keep_springs(np.zeros(0, np.int64), np.zeros(0, np.int64), *np.zeros((3, 0)))

    def _keep(self, **arrays: np.ndarray) -> None:
        """Make ``arrays`` the body's attributes (past `__setattr__`'s checks)."""
        self.__dict__.update(arrays)

    def _keep_springs(self, *arrays: np.ndarray) -> None:
        """Make the spring arrays (ends, stiffness, rest lengths, dashpots) the body's,
        read-only."""
        for array in arrays:
            array.flags.writeable = False
        self._keep(**dict(zip(SPRING_ARRAYS, arrays)), spring_values=arrays[2:])

    def __setattr__(self, name: str, value: object) -> None:
        """``body.masses = 2.0`` or ``body.stiffness = 50.0`` (whole arrays) are checked and
        written into the body's arrays; the ends of the springs cannot be assigned."""
        write = _WHOLE.get(name)
        if write is None:
            super().__setattr__(name, value)
        else:
            write(self, value)

    def __getattr__(self, name: str) -> object:
        """The ends and rest lengths of a grid's springs kept per offset: laid out first."""
        laid_out = name in SPRING_ARRAYS or name == "spring_values"
        if laid_out and self.__dict__.get("grid_springs") is not None:
            self.lay_out_springs()
            return self.__dict__[name]
        raise AttributeError(f"'Body' object has no attribute {name!r}")

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        for name in SPRING_ARRAYS:
            if name in state:
                state[name].flags.writeable = False

    @property
    def n_particles(self) -> int:
        return len(self.positions)

    @property
    def n_springs(self) -> int:
        grid = self.grid_springs
        return len(self.stiffness) if grid is None else grid.count

    def __len__(self) -> int:
        return len(self.positions)

    @property
    def particles(self) -> Rows[Particle]:
        """``particles[i]`` reads/writes particle i's rows of the arrays."""
        return Rows(self, Particle, self.n_particles)

    @property
    def springs(self) -> Rows[Spring]:
        """``springs[k]`` reads/writes spring k's rows of the arrays."""
        return Rows(self, Spring, self.n_springs)

    # ----------------------------------------------------------------- building
    def add_particle(self, particle: Particle) -> int:
        """Add ``particle`` and return its index; the object then reads/writes this body."""
        if not isinstance(particle, Particle):
            raise TypeError(f"add_particle takes a msdlab.Particle, got {type(particle).__name__}")
        if particle.body is not None:
            raise ValueError("this particle already belongs to a body; make a new Particle")
        new = self.add_particles(
            [particle.position], [particle.velocity], particle.mass, particle.fixed
        )
        particle.bind(self, int(new[0]))
        return int(new[0])

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
            raise ValueError(f"positions must have shape (N, 2) or (N, 3), got {positions.shape}")
        if self.dim not in (None, dim):
            raise ValueError(
                f"this body is {self.dim}-D but the new particle has {dim} coordinates; "
                "do not mix 2-D and 3-D particles in one body"
            )
        count, first = len(positions), len(self)
        positions = as_vectors("positions", positions, dim, count)
        velocities = np.zeros((count, dim)) if velocities is None else velocities
        velocities = as_vectors("velocities", velocities, dim, count)
        fixed = np.broadcast_to(np.asarray(fixed, dtype=bool), (count,))
        masses = _per_row("mass", masses, count, MASS_HINT, zero=False)
        if self.dim is None:
            self.dim = dim
            self._keep(positions=np.zeros((0, dim)), velocities=np.zeros((0, dim)))
        velocities = np.where(fixed[:, None], 0.0, velocities)
        new = {"positions": positions, "velocities": velocities, "masses": masses, "fixed": fixed}
        self._keep(**{name: np.concatenate([getattr(self, name), new[name]]) for name in new})
        self.version += 1
        return np.arange(first, first + count)

    def add_spring(self, spring: Spring) -> int:
        """Add ``spring`` and return its index; the object then reads/writes this body."""
        if not isinstance(spring, Spring):
            raise TypeError(f"add_spring takes a msdlab.Spring, got {type(spring).__name__}")
        if spring.body is not None:
            raise ValueError("this spring already belongs to a body; make a new Spring")
        (index,) = self.add_springs(
            [[spring.a, spring.b]], spring.stiffness, spring.rest_length, spring.damping
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
        """Add springs between index pairs (E, 2); rest lengths default to current distances.

        Values are one per spring or one for all (checked once, not per spring).
        """
        pairs = np.asarray(pairs)
        if pairs.size == 0:  # also () and [], which numpy makes float
            pairs = pairs.reshape(0, 2).astype(np.int64)
        if pairs.ndim != 2 or pairs.shape[1] != 2:
            raise ValueError(f"spring pairs must have shape (E, 2), got shape {pairs.shape}")
        if not np.issubdtype(pairs.dtype, np.integer):
            raise TypeError(f"spring ends must be integer particle indices, got {pairs.dtype}")
        count, n = len(pairs), self.n_particles
        if count and (pairs.min() < 0 or pairs.max() >= n):
            bad = np.flatnonzero(((pairs < 0) | (pairs >= n)).any(axis=1))[0]
            raise ValueError(
                f"spring {bad} joins particles {pairs[bad, 0]} and {pairs[bad, 1]}, but the body "
                f"has {n} particles (indices 0 to {n - 1}); add the particles first"
            )
        a, b = pairs[:, 0], pairs[:, 1]
        if (a == b).any():
            same = np.flatnonzero(a == b)[0]
            raise ValueError(
                f"spring {same} joins particle {a[same]} to itself; "
                "a spring needs two different particles"
            )
        if rest_lengths is None:
            rest_lengths = np.linalg.norm(self.positions[a] - self.positions[b], axis=1)
            if count and rest_lengths.min() == 0:
                zero = np.flatnonzero(rest_lengths == 0)[0]
                raise ValueError(
                    f"zero-length spring: particles {a[zero]} and {b[zero]} are at the same "
                    f"position {self.positions[a[zero]].tolist()}; "
                    "move them apart or give rest_length > 0"
                )
        values = _checked_values(count, stiffness, rest_lengths, damping)
        self.lay_out_springs()
        first = self.n_springs
        new = (a.astype(np.int64), b.astype(np.int64), *values.values())
        self._keep_springs(
            *(np.concatenate([getattr(self, n), v]) for n, v in zip(SPRING_ARRAYS, new))
        )
        self.version += 1
        return np.arange(first, first + count)

    def set_springs(self, springs: object = None, **values: object) -> None:
        """Set ``stiffness`` (N/m), ``rest_lengths`` (m) and/or ``spring_damping`` (N·s/m) of
        the springs ``springs`` (indices; default all), each one value or one per spring.

        A grid keeps its springs per offset when every spring gets one value; an edit of
        some springs, or per spring, lays them out first (`lay_out_springs`).
        """
        unknown = set(values) - set(VALUE_HINTS)
        if unknown:
            raise TypeError(f"set_springs sets {', '.join(VALUE_HINTS)}, not {sorted(unknown)}")
        chosen = np.arange(self.n_springs)[slice(None) if springs is None else springs]
        checked = {name: _checked_value(name, v, len(chosen)) for name, v in values.items()}
        grid = self.grid_springs
        one = {
            name: float(v[0]) for name, v in checked.items() if len(chosen) and np.all(v == v[0])
        }
        if grid is not None and springs is None and len(one) == len(checked):
            self._keep_grid(grid.with_values(**one))
            return
        self.lay_out_springs()
        for name, value in checked.items():
            array = getattr(self, name)
            array.flags.writeable = True  # the body's own array, read-only to others
            array[chosen] = value
            array.flags.writeable = False
        self.version += 1

    def lay_out_springs(self) -> None:
        """Write the springs of `grid_springs` into per-spring arrays (a no-op without).

        The springs keep their order and values, so the kernels compute the same (and
        ``version`` stays).
        """
        grid = self.grid_springs
        if grid is None:
            return
        blocks = [np.zeros((0, 2), np.int64), *grid_pair_blocks(grid.shape, grid.offsets)]
        pairs, counts = np.concatenate(blocks), [len(block) for block in blocks[1:]]
        self._keep_springs(
            pairs[:, 0].copy(),
            pairs[:, 1].copy(),
            np.full(grid.count, grid.stiffness),
            np.repeat(grid.rest_lengths, counts),
            np.full(grid.count, grid.damping),
        )
        self.grid_springs = None

    def _keep_grid(self, grid: GridSprings) -> None:
        """Keep the springs per offset (``grid``): one stiffness and dashpot for all springs,
        read as broadcast arrays (no memory per spring); the ends and rest lengths come
        when laid out (`__getattr__`)."""
        for name in ("spring_a", "spring_b", "rest_lengths", "spring_values"):
            self.__dict__.pop(name, None)
        self._keep(
            grid_springs=grid,
            stiffness=np.broadcast_to(grid.stiffness, (grid.count,)),
            spring_damping=np.broadcast_to(grid.damping, (grid.count,)),
        )
        self.version += 1

    def new_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Empty arrays (N, d) for the next positions and velocities, for a kernel to write
        a step's new state into; `store_state` then makes them the body's own, uncopied."""
        new = (np.empty_like(self.positions), np.empty_like(self.velocities))
        self.__dict__["_new_state"] = new  # every step: past `__setattr__`
        return new

    def store_state(self, positions: np.ndarray, velocities: np.ndarray) -> None:
        """Make ``positions`` (m) and ``velocities`` (m/s), (N, d), the body's state.

        The arrays of the last `new_state` become the body's own; others are copied
        in. Arrays read from the body before may then keep the old state.
        """
        new, self.__dict__["_new_state"] = self._new_state, ()  # every step: past `__setattr__`
        if new and positions is new[0] and velocities is new[1] and len(new[0]) == len(self):
            self.__dict__.update(positions=positions, velocities=velocities)
        else:
            self.positions[...], self.velocities[...] = positions, velocities

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
        The springs are kept per offset (`grid_springs`) until laid out.
        """
        shape = grid_shape(shape)
        spacing = check_positive("spacing", spacing, "Grid spacing is in m and must be > 0.")
        origin = np.zeros(len(shape)) if origin is None else np.asarray(origin, dtype=float)
        if origin.shape != (len(shape),):
            raise ValueError(f"origin must have {len(shape)} coordinates, got {origin.tolist()}")
        offsets = neighbour_offsets(len(shape), neighbours)
        body = cls()
        body.add_particles(grid_positions(shape, spacing, origin), masses=mass)
        k = _per_row("stiffness", stiffness, 1, f"Use k >= 0 in N/m, e.g. {GRID_EXAMPLE}.")
        c = _per_row("damping", damping, 1, "Use a dashpot c >= 0 in N·s/m, e.g. damping=0.1.")
        rest = spacing * np.sqrt((offsets**2).sum(axis=1))
        body._keep_grid(GridSprings(shape, offsets, rest, float(k[0]), float(c[0])))
        body.grid_shape = shape
        return body

    # ----------------------------------------------------------------- helpers
    def copy(self) -> Body:
        """An independent copy of the body (state and springs)."""
        body = Body(self.dim)
        body.add_particles(self.positions, self.velocities, self.masses, self.fixed)
        if self.grid_springs is None:
            body._keep_springs(*(getattr(self, name).copy() for name in SPRING_ARRAYS))
        else:
            body._keep_grid(self.grid_springs)
        body.grid_shape = self.grid_shape
        return body

    def center_of_mass(self) -> np.ndarray:
        """Mass-weighted mean position (m)."""
        return self.masses @ self.positions / self.masses.sum()

    def rotate(self, rotation: np.ndarray, about: Sequence[float] | None = None) -> None:
        """Rotate positions and velocities by a (d, d) rotation matrix about a point
        (default: the centre of mass). See `rotation_matrix`."""
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
        if self._incidence is None or self._incidence[0] != self.version:
            ends = np.concatenate([self.spring_a, self.spring_b])
            start = np.zeros(self.n_particles + 1, dtype=np.int64)
            np.cumsum(np.bincount(ends, minlength=self.n_particles), out=start[1:])
            springs = np.argsort(ends, kind="stable") % max(self.n_springs, 1)
            self._incidence = (self.version, start, springs)
        return self._incidence[1], self._incidence[2]

    def springs_touching(self, particles: np.ndarray) -> np.ndarray:
        """Indices of the springs with an end in ``particles`` (sorted, unique)."""
        start, springs = self.incident_springs()
        if len(particles) == 1:  # one slice (a wall's bounce asks for one particle at a time)
            return np.unique(springs[start[particles[0]] : start[particles[0] + 1]])
        counts = start[particles + 1] - start[particles]
        first = np.repeat(start[particles] - (np.cumsum(counts) - counts), counts)
        return np.unique(springs[first + np.arange(counts.sum())])

    def __repr__(self) -> str:
        kind = f"{self.dim}-D" if self.dim else "empty"
        grid = f", grid {self.grid_shape}" if self.grid_shape else ""
        return f"<Body {kind}: {self.n_particles} particles, {self.n_springs} springs{grid}>"


def _checked_value(name: str, values: object, count: int) -> np.ndarray:
    """Spring value ``name`` for ``count`` springs, checked (rest lengths > 0, others >= 0)."""
    label = {"rest_lengths": "rest length", "spring_damping": "damping"}.get(name, name)
    return _per_row(label, values, count, VALUE_HINTS[name], zero=name != "rest_lengths")


def _checked_values(count: int, k: object, rest: object, c: object) -> dict[str, np.ndarray]:
    return {name: _checked_value(name, v, count) for name, v in zip(VALUE_HINTS, (k, rest, c))}


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
