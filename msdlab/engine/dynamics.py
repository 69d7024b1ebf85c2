"""Dynamics: the equations of motion of a body, a = F(x, v) / m."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from . import equations
from .backends.choice import kernel_left_to_msdlab, make_kernel
from .backends.contract import SpringKernel, Update
from .backends.jacobian import JacobianPattern
from .backends.numpy import NumpyKernel
from .model.body import Body
from .model.forces import Force


def keep_acceleration(
    x: np.ndarray, v: np.ndarray, a: np.ndarray, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """The update that returns the acceleration a (m/s²) in place of the new positions:
    through the backend's `advance`, a = F/m alone (on numba, in one compiled loop)."""
    return a, v


class Dynamics:
    """Newton's second law for a body: a_i = F_i / m_i, eq. (1.1) with masses.

    F is the sum of the spring and dashpot forces (eq. 1.2) and the external
    ``forces``. Fixed particles have zero inverse mass, so they get zero
    acceleration. Integrators call `acceleration` or `advance` (and `force`,
    `jacobians` or `implicit_matrix`, `masses`, `free` for implicit methods).

    ``kernel`` picks the backend (`msdlab.engine.backends.contract`): "numba" (compiled,
    threaded) or "numpy" (readable); the default is ``MSDLAB_KERNEL`` or "numba".
    Both apply the same `msdlab.engine.equations`; nothing here depends on which runs:
    the springs' forces, energy and Jacobians and a step's a = F/m and update come
    from the backend; the uniform fields and the other forces are gathered here.
    """

    def __init__(self, body: Body, forces: Sequence[Force] = (), kernel: str | None = None) -> None:
        self.body = body
        self.forces = list(forces)
        self.springs: SpringKernel = make_kernel(kernel)
        self.springs.load(body.positions, body.velocities)  # the state it steps
        self.chosen = self.springs
        # the kernel of a step while a debugger traces the program (`Simulation.step`)
        self.readable = NumpyKernel() if kernel_left_to_msdlab(kernel) else None
        self.max_stretch = 0.0  # largest |d|/l seen in the last force evaluation
        # The power (W) each mechanism takes out at the state a step starts from, by ledger
        # name: the dashpots' ("dashpot") and each force's, from the last pass there.
        self.opening: dict[str, float] | None = None
        # The new (x, v) the backend's last `advance` made: arrays no one else holds.
        self.advanced: tuple[np.ndarray | None, np.ndarray | None] = (None, None)
        self._pattern: JacobianPattern | None = None

    @property
    def kernel(self) -> str:
        """Name of the spring kernel in use, "numba" or "numpy"."""
        return self.springs.name

    @property
    def masses(self) -> np.ndarray:
        """Masses (N,) in kg."""
        return self.body.masses

    @property
    def free(self) -> np.ndarray:
        """True for particles that may move (N,)."""
        return ~self.body.fixed

    def force(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Total force on each particle (N, d) in N."""
        total = np.zeros_like(x)
        sums = self.springs.spring_forces(self.body, x, v, total)
        powers = {"dashpot": sums.power}
        for force in self.forces:
            _count(powers, force.ledger_name, force.add_to(self.body, x, v, total))
        self.max_stretch = sums.stretch
        start = self.springs.state()  # a pass there is the one a step starts with
        if x is start[0] and v is start[1]:
            self.opening = powers
        return total

    def acceleration(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Acceleration of each particle (N, d) in m/s², a = (F + m·g)/m: F the spring,
        dashpot and other forces, g the uniform fields (gravity, `Force.uniform_acceleration`);
        zero for fixed particles. The backend's `advance` with `keep_acceleration`."""
        return self.advance(keep_acceleration, x, v, 0.0)[0]

    def advance(
        self, update: Update, x: np.ndarray, v: np.ndarray, dt: float, *coefficients: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """``update(x, v, a, dt, *coefficients)`` with a = `acceleration` (x, v): one step.

        ``update`` is a function of arrays or numbers (like `integrators.Verlet.update`)
        returning the new (x, v). The backend's `SpringKernel.advance` runs it: the numpy
        backend on whole arrays, the numba backend compiled into one loop with the springs'
        pass and a. The uniform fields go in as g, the other forces as an array.

        A pass at the state the backend steps (where a step starts) keeps the power each mechanism
        takes out there in `opening`, for the energy ledger: the dashpots' from the
        backend's pass over the springs, each force's from its `Force.add_to`.
        """
        field, others = np.zeros(x.shape[1]), None  # Σ g (m/s²); the other forces (N)
        powers = {"dashpot": 0.0}
        for force in self.forces:
            g = force.uniform_acceleration(self.body)
            if g is not None:
                field += g
                continue
            others = np.zeros_like(x) if others is None else others
            _count(powers, force.ledger_name, force.add_to(self.body, x, v, others))
        step = self.springs.advance(update, self.body, x, v, field, dt, coefficients, others)
        self.max_stretch, powers["dashpot"] = step.stretch, step.power
        self.advanced = (step.x, step.v)
        start = self.springs.state()  # a pass there is the one a step starts with
        if x is start[0] and v is start[1]:
            self.opening = powers
        return step.x, step.v

    def powers_now(self) -> dict[str, float]:
        """The power (W) each mechanism takes out at the state the backend steps, by ledger
        name, from a pass of its own there (kept in `opening`)."""
        self.force(*self.springs.state())
        return self.opening

    def choose(self, kernel: SpringKernel) -> None:
        """Step with ``kernel`` from now on, from the state the one in use had."""
        if kernel is not self.springs:
            kernel.load(*self.springs.state())
            self.springs = kernel

    def acceleration_of(
        self,
        particles: np.ndarray,
        x: np.ndarray,
        v: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> np.ndarray:
        """Acceleration (M, d) of some particles only, from the springs touching them.

        ``springs`` may pass ``body.springs_touching(particles)`` when it is known.
        """
        if springs is None:
            springs = self.body.springs_touching(particles)
        total = np.zeros_like(x)
        self.springs.spring_forces(self.body, x, v, total, springs)
        for force in self.forces:
            force.add_to(self.body, x, v, total)
        masses, free = self.body.masses[particles, None], ~self.body.fixed[particles, None]
        return equations.acceleration(total[particles], masses, free)

    def jacobians(self, x: np.ndarray, v: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v, sparse (N·d × N·d), for implicit integrators.

        The sparsity pattern of the springs is built once per topology and refilled.
        """
        jx, jv = self._spring_jacobians(x)
        for force in self.forces:
            fx, fv = force.jacobians(self.body, x, v)
            jx = jx if fx is None else jx + fx
            jv = jv if fv is None else jv + fv
        return jx, jv

    def implicit_matrix(
        self, x: np.ndarray, v: np.ndarray, h_v: float, h_x: float
    ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """M - h_v ∂F/∂v - h_x ∂F/∂x (N·d × N·d, sparse) and ∂F/∂x, for implicit
        integrators (linearised backward Euler: h_v = dt, h_x = dt², in s and s²).

        The springs' Jacobians share one sparsity that holds the whole diagonal,
        so this is arithmetic on their values; forces add theirs as matrices.
        """
        jx, jv = self._spring_jacobians(x)
        values = -h_x * jx.data
        if jv.nnz:  # dashpots: on the same pattern
            values -= h_v * jv.data
        values[self._pattern.diagonal] += np.repeat(self.masses, x.shape[1])
        matrix = self._pattern.matrix(values)
        for force in self.forces:
            fx, fv = force.jacobians(self.body, x, v)
            jx = jx if fx is None else jx + fx
            matrix = matrix if fx is None else matrix - h_x * fx
            matrix = matrix if fv is None else matrix - h_v * fv
        return matrix, jx

    def _spring_jacobians(self, x: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v of the springs, on their pattern (rebuilt when they change)."""
        if self._pattern is None or self._pattern.version != self.body.version:
            self._pattern = JacobianPattern(self.body)
        return self.springs.jacobians(self.body, x, self._pattern)

    def elastic_energy(self, x: np.ndarray, springs: np.ndarray | None = None) -> float:
        """Energy stored in the springs (or in the given ones), Σ ½ k (|x_a - x_b| - l)² (J)."""
        return self.springs.elastic_energy(self.body, x, springs)

    def potential_energy(self, x: np.ndarray) -> float:
        """Elastic energy of the springs plus the potential of the forces (J)."""
        return self.elastic_energy(x) + sum(
            force.potential_energy(self.body, x) for force in self.forces
        )


def _count(powers: dict[str, float], name: str, power: float | None) -> None:
    """Add ``power`` (W; None or 0 for a conservative force) to ``powers[name]``."""
    if power:
        powers[name] = powers.get(name, 0.0) + power
