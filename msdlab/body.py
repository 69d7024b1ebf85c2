"""Body: particles and springs, stored as arrays (one row per particle / spring)."""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Generic, TypeVar

import numpy as np

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
from .tracked import TrackedArray

Item = TypeVar("Item", Particle, Spring)
MASS_HINT = "To pin a particle use fixed=True instead of a zero mass."
FIELDS = {  # the arrays of a body and their types: one row per particle / per spring
    "particles": {"positions": float, "velocities": float, "masses": float, "fixed": bool},
    "springs": {
        "spring_a": np.int64,
        "spring_b": np.int64,
        "stiffness": float,
        "rest_lengths": float,
        "spring_damping": float,
    },
}


_SPRING_VALUES = ("stiffness", "rest_lengths", "spring_damping")
_VIEWS = {*FIELDS["particles"], *FIELDS["springs"], "spring_values"}  # kept in the __dict__


def _per_row(name: str, values: object, count: int, hint: str, zero: bool = True) -> np.ndarray:
    """``values`` checked finite and >= 0 (> 0 unless ``zero``): one value or ``count``."""
    array = check_non_negative(name, values, hint, zero=zero)
    if array.ndim and array.shape != (count,):
        raise ValueError(f"{name} needs one value or one per row ({count}), got {array.shape}")
    return array


def _pin(body: Body, fixed: object, count: int) -> np.ndarray:
    """The fixed mask (N,) to store; pinned particles stop (their velocity becomes zero)."""
    mask = np.broadcast_to(np.asarray(fixed, dtype=bool), (count,))
    body.velocities[mask] = 0.0
    return mask


class _Rows:
    """A body array as an attribute: a view of the used rows of a buffer that grows.

    Reading ``body.<name>`` finds the view in the body's ``__dict__``, where
    `Body` puts it whenever the rows change: the view is valid until the body
    grows. Only the spring arrays of a grid body that keeps its springs per
    offset (`Body.grid_springs`) are missing there; reading one lays them out
    first. Assigning the whole array goes through ``check(body, value, rows)``;
    without a check the array is read-only. Spring values are `TrackedArray`
    views, so writes to them count in ``body.parameters_version``.
    """

    def __init__(self, doc: str, check: Callable[[Body, Any, int], Any] | None = None) -> None:
        self.__doc__, self.check = doc, check

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name
        self.kind = "particles" if name in FIELDS["particles"] else "springs"

    def __get__(self, body: Body | None, owner: type | None = None) -> Any:
        if body is None:
            return self
        body.lay_out_springs()
        return body.__dict__[self.name]

    def view(self, body: Body) -> np.ndarray:
        """The used rows of the body's buffer, as the attribute shows them."""
        view = body._buffers[self.name][: body._size[self.kind]]
        if self.check is None:
            view.flags.writeable = False
        elif self.kind == "springs":
            return TrackedArray.of(view, body._spring_values_edited)
        return view

    def assign(self, body: Body, value: object) -> None:
        """``body.<name> = value``: check the whole array and write it into the rows."""
        if self.check is None:
            raise AttributeError(f"body.{self.name} is read-only; add springs to change it")
        rows = getattr(body, self.name)
        rows[...] = self.check(body, value, len(rows))


class Body:
    """A mass-spring body in 2-D or 3-D (fixed by the first particle added).

    The state lives in arrays, so the whole body is updated at once (writeable
    views, valid until the body grows). ``particles[i]`` and ``springs[k]`` are
    objects reading and writing the same rows.
    """

    positions = _Rows(
        "Positions (N, d) in m.", lambda body, x, n: as_vectors("positions", x, body.dim or 3, n)
    )
    velocities = _Rows(
        "Velocities (N, d) in m/s; zero for fixed particles.",
        lambda body, v, n: np.where(
            body.fixed[:, None], 0.0, as_vectors("velocities", v, body.dim or 3, n)
        ),
    )
    masses = _Rows(
        "Masses (N,) in kg.", lambda body, m, n: _per_row("mass", m, n, MASS_HINT, zero=False)
    )
    fixed = _Rows("True for pinned particles (N,); pinning zeroes their velocity.", _pin)
    spring_a = _Rows("First particle of each spring (E,), read-only.")
    spring_b = _Rows("Second particle of each spring (E,), read-only.")
    stiffness = _Rows(
        "Spring stiffness k (E,) in N/m.",
        lambda body, k, n: _per_row("stiffness", k, n, "Use k >= 0 (N/m)."),
    )
    rest_lengths = _Rows(
        "Spring rest lengths l (E,) in m.",
        lambda body, rest, n: _per_row("rest length", rest, n, "It is in m.", zero=False),
    )
    spring_damping = _Rows(
        "Dashpot coefficient c along each spring (E,) in N·s/m.",
        lambda body, c, n: _per_row("damping", c, n, "Use a dashpot coefficient c >= 0 (N·s/m)."),
    )

    spring_values = _Rows(
        "Stiffness (N/m), rest lengths (m) and dashpots (N·s/m) (E,) as plain arrays to read. "
        "Write through `stiffness`, `rest_lengths` and `spring_damping`, which count edits."
    )

    def __init__(self, dim: int | None = None) -> None:
        if dim not in (None, 2, 3):
            raise ValueError(f"a body is 2-D or 3-D, got dim = {shown(dim)}")
        self.dim = dim
        self.grid_shape: tuple[int, ...] | None = None
        self.topology_version = 0  # grows whenever particles or springs are added
        self.parameters_version = 0  # grows whenever the spring values are edited
        self.grid_springs: GridSprings | None = None  # `Body.grid`'s springs, until laid out
        self._size = {"particles": 0, "springs": 0}
        self._buffers: dict[str, np.ndarray] = {}
        self._capacity = {"particles": 0, "springs": 0}
        self._reserve("particles", 0)
        self._reserve("springs", 0)
        self._incidence: tuple[int, np.ndarray, np.ndarray] | None = None
        self._new_state: tuple[np.ndarray, ...] = ()  # see `new_state`

    @property
    def n_particles(self) -> int:
        return self._size["particles"]

    @property
    def n_springs(self) -> int:
        return self._size["springs"]

    def __len__(self) -> int:
        return self.n_particles

    def __setattr__(self, name: str, value: object) -> None:
        """``body.masses = 2.0`` (a whole array) is checked and written into its rows."""
        rows = getattr(type(self), name, None)
        if isinstance(rows, _Rows):
            rows.assign(self, value)
        else:
            super().__setattr__(name, value)

    def _spring_values_edited(self) -> None:
        """Count an in-place write to the spring values (see `tracked.TrackedArray`)."""
        self.parameters_version += 1

    @property
    def particles(self) -> _Items[Particle]:
        """``particles[i]`` reads/writes particle i's rows of the arrays."""
        return _Items(self, Particle, self.n_particles)

    @property
    def springs(self) -> _Items[Spring]:
        """``springs[k]`` reads/writes spring k's rows of the arrays."""
        return _Items(self, Spring, self.n_springs)

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
        count = len(positions)
        positions = as_vectors("positions", positions, dim, count)
        velocities = 0.0 if velocities is None else as_vectors("velocities", velocities, dim, count)
        fixed = np.broadcast_to(np.asarray(fixed, dtype=bool), (count,))
        if self.dim is None:
            self.dim = dim
            self._reserve("particles", 0)  # the empty buffers, now with d columns
        return self._append(
            "particles",
            count,
            positions=positions,
            velocities=np.where(fixed[:, None], 0.0, velocities),
            masses=_per_row("mass", masses, count, MASS_HINT, zero=False),
            fixed=fixed,
        )

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
        return self._append(
            "springs",
            count,
            spring_a=a,
            spring_b=b,
            stiffness=Body.stiffness.check(self, stiffness, count),
            rest_lengths=Body.rest_lengths.check(self, rest_lengths, count),
            spring_damping=Body.spring_damping.check(self, damping, count),
        )

    def _append(self, kind: str, count: int, **columns: object) -> np.ndarray:
        """Add ``count`` rows of ``kind`` holding ``columns``; return their indices."""
        if kind == "springs":
            self.lay_out_springs()
        indices = self._write(kind, count, **columns)
        self.topology_version += 1
        return indices

    def _write(self, kind: str, count: int, **columns: object) -> np.ndarray:
        """Write ``columns`` into the next ``count`` rows of ``kind``; return their indices."""
        start = self._size[kind]
        if start + count > self._capacity[kind]:
            self._reserve(kind, max(start + count, 2 * start, 8))
        for name, values in columns.items():
            self._buffers[name][start : start + count] = values
        self._size[kind] += count
        self._show(kind)
        return np.arange(start, start + count)

    def lay_out_springs(self) -> None:
        """Write the springs of `grid_springs` into per-spring arrays (a no-op without).

        Reading any spring array does this first; the springs keep their order
        and values, so nothing changes for the kernels (no version grows).
        """
        grid = self.grid_springs
        if grid is None:
            return
        self.grid_springs = None
        self._size["springs"] = 0
        self._reserve("springs", grid.count)  # exactly: no regrowth
        values = {"stiffness": grid.stiffness, "spring_damping": grid.damping}
        for rest, pairs in zip(grid.rest_lengths, grid_pair_blocks(grid.shape, grid.offsets)):
            ends = {"spring_a": pairs[:, 0], "spring_b": pairs[:, 1]}
            self._write("springs", len(pairs), rest_lengths=rest, **ends, **values)

    def new_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Empty arrays (N, d) for the next positions and velocities, for a kernel to write
        a step's new state into: `store_state` then makes them the body's own, uncopied."""
        shape = (self._size["particles"], self.dim or 3)
        # straight into __dict__: `__setattr__` only checks body arrays, and this is every step
        self.__dict__["_new_state"] = (np.empty(shape), np.empty(shape))
        return self._new_state

    def store_state(self, positions: np.ndarray, velocities: np.ndarray) -> None:
        """Make ``positions`` (m) and ``velocities`` (m/s), (N, d), the body's state.

        The arrays of the last `new_state` become the body's own; others are copied
        in. Arrays read from the body before may then keep the old state.
        """
        new, self.__dict__["_new_state"] = self._new_state, ()
        adopt = new and positions is new[0] and velocities is new[1]
        if adopt and len(positions) == self._size["particles"]:
            self._buffers["positions"] = self.__dict__["positions"] = positions
            self._buffers["velocities"] = self.__dict__["velocities"] = velocities
            self._capacity["particles"] = self._size["particles"]  # adding particles regrows all
        else:
            self.positions[...] = positions
            self.velocities[...] = velocities

    def _keep_grid_springs(self, grid: GridSprings) -> None:
        """Use ``grid``'s springs, kept per offset, as the body's (it has none yet)."""
        self.grid_springs = grid
        self._size["springs"] = grid.count
        self.topology_version += 1
        self._show("springs")

    def _show(self, kind: str) -> None:
        """Put the views of the used rows of ``kind`` (see `_Rows`) in the body's attributes;
        a grid's springs kept per offset have none until they are laid out."""
        if kind == "springs" and self.grid_springs is not None:
            for name in (*FIELDS[kind], "spring_values"):
                self.__dict__.pop(name, None)
            return
        for name in FIELDS[kind]:
            self.__dict__[name] = getattr(Body, name).view(self)
        if kind == "springs":  # the same rows as plain arrays, for kernels to read
            used = self._size[kind]
            self.__dict__["spring_values"] = tuple(
                self._buffers[name][:used] for name in _SPRING_VALUES
            )

    def __getstate__(self) -> dict[str, Any]:
        """The body without its views (they would be pickled as copies, not views)."""
        return {name: value for name, value in self.__dict__.items() if name not in _VIEWS}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._show("particles")
        self._show("springs")

    def _reserve(self, kind: str, capacity: int) -> None:
        """Grow the buffers of ``kind`` to hold ``capacity`` rows (their used rows kept)."""
        used = self._size[kind]
        for name, dtype in FIELDS[kind].items():
            columns = (self.dim or 3,) if name in ("positions", "velocities") else ()
            grown = np.empty((capacity, *columns), dtype)  # rows past `used` are never read
            if used:
                grown[:used] = self._buffers[name][:used]
            self._buffers[name] = grown
        self._capacity[kind] = capacity
        self._show(kind)

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
        The springs are kept per offset (`grid_springs`) until a spring array is read.
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
        body._keep_grid_springs(GridSprings(shape, offsets, rest, float(k), float(c)))
        body.grid_shape = shape
        return body

    # ----------------------------------------------------------------- helpers
    def copy(self) -> Body:
        """An independent copy of the body (state and springs)."""
        body = Body(self.dim)
        particles = {name: getattr(self, name) for name in FIELDS["particles"]}
        body._append("particles", self.n_particles, **particles)
        if self.grid_springs is None:
            springs = {name: getattr(self, name) for name in FIELDS["springs"]}
            body._append("springs", self.n_springs, **springs)
        else:
            body._keep_grid_springs(self.grid_springs)
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
        if self._incidence is None or self._incidence[0] != self.topology_version:
            ends = np.concatenate([self.spring_a, self.spring_b])
            start = np.zeros(self.n_particles + 1, dtype=np.int64)
            np.cumsum(np.bincount(ends, minlength=self.n_particles), out=start[1:])
            springs = np.argsort(ends, kind="stable") % max(self.n_springs, 1)
            self._incidence = (self.topology_version, start, springs)
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
