"""Body: particles as arrays (one row each) and one spring set (an edge list or a lattice)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .bound import Rows
from .errors import as_vectors, shown
from .lattice import LatticeSprings, grid_positions, grid_shape, lattice_springs
from .particle import Particle, checked_masses, particle_arrays
from .rotation import checked_rotation
from .spring import Spring
from .springs import EdgeSprings, checked_value, copied, edge_springs, incidence, touching

STATE = ("positions", "velocities", "masses", "fixed")  # the particles' arrays


class Body:
    """A mass-spring body in 2-D or 3-D (fixed by the first particle added).

    The particles are arrays read and written in place: ``positions`` (N, d) in m,
    ``velocities`` (N, d) in m/s, ``masses`` (N,) in kg, ``fixed`` (N,). The springs are
    ``spring_set``: an edge list (`springs.EdgeSprings`) or, from `Body.grid`, a lattice
    (`lattice.LatticeSprings`, values per neighbour offset), changed only by the methods
    that add one to ``version``. ``particles[i]`` and ``springs[k]`` read and write one.
    """

    def __init__(self, dim: int | None = None) -> None:
        if dim not in (None, 2, 3):
            raise ValueError(f"a body is 2-D or 3-D, got dim = {shown(dim)}")
        self.dim, self.version = dim, 0  # the version grows with every addition or edit
        self.spring_set: EdgeSprings | LatticeSprings = EdgeSprings.empty()
        self.positions, self.velocities = np.zeros((0, dim or 3)), np.zeros((0, dim or 3))
        self.masses, self.fixed = np.zeros(0), np.zeros(0, bool)
        self._incidence: tuple[int, ...] = (-1,)  # version, `springs.incidence`

    def __setattr__(self, name: str, value: object) -> None:
        """``body.positions = ...`` (or velocities, masses, fixed): checked, then written
        into the body's array in place; a new ``spring_set`` adds one to ``version``; other
        attributes are set as usual."""
        if name == "spring_set" and name in vars(self):
            vars(self)["version"] += 1
        if name not in STATE or name not in vars(self):
            return super().__setattr__(name, value)
        if name in ("positions", "velocities"):
            value = as_vectors(name, value, self.dim or 3, len(self))
        getattr(self, name)[...] = checked_masses(value, len(self)) if name == "masses" else value
        self.velocities[self.fixed] = 0.0  # pinned particles stop

    @property
    def n_springs(self) -> int:
        return self.spring_set.count

    def __len__(self) -> int:
        return len(self.positions)

    n_particles = property(__len__, doc="Number of particles N.")

    @property
    def particles(self) -> Rows[Particle]:
        """``particles[i]`` reads/writes particle i's rows of the arrays."""
        return Rows(self, Particle, self.n_particles)

    @property
    def springs(self) -> Rows[Spring]:
        """``springs[k]`` reads/writes spring k of the spring set."""
        return Rows(self, Spring, self.n_springs)

    def add_particle(self, particle: Particle) -> int:
        """Add ``particle`` and return its index; the object then reads/writes this body."""
        Particle.check_new(particle, "add_particle")
        (index,) = self.add_particles(
            [particle.position], [particle.velocity], particle.mass, particle.fixed
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
        new = particle_arrays(self.dim, positions, velocities, masses, fixed)
        count, first = len(new[0]), len(self)
        if self.dim is None:
            self.dim = new[0].shape[1]
            vars(self).update(positions=new[0][:0], velocities=new[1][:0])
        joined = (np.concatenate([getattr(self, name), array]) for name, array in zip(STATE, new))
        vars(self).update(zip(STATE, joined))  # new arrays: past `__setattr__`
        self.version += 1
        return np.arange(first, first + count)

    def add_spring(self, spring: Spring) -> int:
        """Add ``spring`` and return its index; the object then reads/writes this body."""
        Spring.check_new(spring, "add_spring")
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
        """Add springs between index pairs (E, 2) to the edge list; rest lengths default to
        the current distances. Values are one per spring or one for all."""
        new = edge_springs(self.positions, pairs, stiffness, rest_lengths, damping)
        first = self.n_springs
        self.spring_set = self.spring_set.joined(new)
        self.version += 1
        return np.arange(first, first + new.count)

    def set_springs(self, springs: object = None, **values: object) -> None:
        """Set ``stiffness`` (N/m), ``rest_lengths`` (m) and/or ``damping`` (N·s/m) of the
        springs ``springs`` (indices; default all), each one value or one per spring.
        A lattice takes one value for all its springs (see `springs_as_edges`)."""
        chosen = None if springs is None else np.arange(self.n_springs)[springs]
        count = self.n_springs if chosen is None else len(chosen)
        checked = {name: checked_value(name, value, count) for name, value in values.items()}
        self.spring_set.set_values(chosen, **checked)
        self.version += 1

    def edges(self) -> EdgeSprings:
        """The springs as an edge list: the body's own, or a lattice's laid out (not kept)."""
        return self.spring_set.edges()

    def springs_as_edges(self) -> EdgeSprings:
        """Make the springs an edge list, to edit single springs or add some; return it."""
        edges = self.spring_set.edges()
        if edges is not self.spring_set:
            self.spring_set = edges
        return edges

    def store_state(self, positions: np.ndarray, velocities: np.ndarray) -> None:
        """Make ``positions`` (m) and ``velocities`` (m/s), float arrays (N, d), the body's
        state, uncopied: the caller hands them over and writes them no more (a simulation's
        new state after a step; arrays read before keep the old state)."""
        for name, array in (("positions", positions), ("velocities", velocities)):
            if array.shape != self.positions.shape or array.dtype != self.positions.dtype:
                raise ValueError(
                    f"a state of {array.dtype} {array.shape} cannot be the body's {name}: it "
                    f"has {len(self)} particles in {self.positions.shape[1]}-D, float64"
                )
        vars(self).update(positions=positions, velocities=velocities)  # past `__setattr__`

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
        """A body from positions (N, d) and springs: index pairs (E, 2) and values, or a lattice."""
        body = cls()
        body.add_particles(positions, velocities, masses, fixed)
        if isinstance(springs, LatticeSprings):
            body.spring_set = springs
        else:
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
        """A 2-D or 3-D grid of particles ``origin + spacing·(i, j[, k])``, C order, joined at
        rest by a lattice (`lattice.LatticeSprings`) to its ``neighbours``: squared distances
        in grid units, 1 axis springs (rest length = spacing), 2 face diagonals (√2·spacing),
        3 body diagonals (√3·spacing)."""
        shape = grid_shape(shape)
        body = cls()
        body.add_particles(grid_positions(shape, spacing, origin), masses=mass)
        body.spring_set = lattice_springs(shape, neighbours, spacing, stiffness, damping)
        return body

    def copy(self) -> Body:
        """An independent copy of the body (particles and springs)."""
        body = Body(self.dim)
        body.add_particles(self.positions, self.velocities, self.masses, self.fixed)
        body.spring_set = copied(self.spring_set)
        return body

    def center_of_mass(self) -> np.ndarray:
        """Mass-weighted mean position (m)."""
        return self.masses @ self.positions / self.masses.sum()

    def rotate(self, rotation: np.ndarray, about: Sequence[float] | None = None) -> None:
        """Rotate positions and velocities by a (d, d) rotation matrix about a point
        (default: the centre of mass). See `rotation_matrix`."""
        rotation = checked_rotation(rotation, self.dim)
        centre = self.center_of_mass() if about is None else np.asarray(about, dtype=float)
        self.positions[:] = (self.positions - centre) @ rotation.T + centre
        self.velocities[:] = self.velocities @ rotation.T

    def springs_touching(self, particles: np.ndarray) -> np.ndarray:
        """Indices of the springs with an end in ``particles`` (sorted, unique)."""
        return touching(*self._lists()[:2], particles)

    def neighbours(self, particles: np.ndarray) -> np.ndarray:
        """Indices of the particles a spring joins to ``particles``, not among them."""
        start, _, partners = self._lists()
        return np.setdiff1d(touching(start, partners, particles), particles)

    def _lists(self) -> tuple[np.ndarray, ...]:
        """The CSR lists of `springs.incidence`, made again after an edit."""
        if self._incidence[0] != self.version:
            self._incidence = (self.version, *incidence(self.edges(), self.n_particles))
        return self._incidence[1:]

    def __repr__(self) -> str:
        kind = f"{self.dim}-D" if self.dim else "empty"
        lattice = isinstance(self.spring_set, LatticeSprings)
        grid = f", grid {self.spring_set.shape}" if lattice else ""
        return f"<Body {kind}: {self.n_particles} particles, {self.n_springs} springs{grid}>"
