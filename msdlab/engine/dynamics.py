"""Dynamics: the equations of motion of a body, a = F(x, v) / m."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import scipy.sparse as sp

from . import equations
from .backends.choice import kernel_left_to_msdlab, make_kernel, stepping_backend
from .backends.contract import SpringKernel, Update
from .backends.layout import Layout
from .backends.numpy import NumpyKernel
from .model.body import Body
from .model.forces import Force

if TYPE_CHECKING:
    from .integrators import Integrator


def keep_acceleration(
    x: np.ndarray, v: np.ndarray, a: np.ndarray, dt: float
) -> tuple[np.ndarray, np.ndarray]:
    """The update that returns the acceleration a (m/s²) in place of the new positions:
    through the backend's `advance`, a = F/m alone (on numba, in one compiled loop)."""
    return a, v


class Step(NamedTuple):
    """One step of an integrator (`Dynamics.step`), as the simulation books it."""

    x: np.ndarray  # the new positions (N, d) in m, arrays of the step's own
    v: np.ndarray  # the new velocities (N, d) in m/s
    stretch: float  # the largest |x_a - x_b| / l of the step's passes over the springs
    # The power (W) each mechanism took out at the step's first pass (where it starts), by
    # ledger name: the dashpots' ("dashpot") and each force's; None if it took no pass.
    powers: dict[str, float] | None


class Made(tuple):
    """The new (x, v) a backend's `advance` made: arrays no one else holds."""


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
        self.chosen: SpringKernel = make_kernel(kernel)
        self.springs = self.chosen  # the backend of the last step (`stepping_backend`)
        # the backend of a step while a debugger traces the program, if none was asked for
        self.readable = NumpyKernel() if kernel_left_to_msdlab(kernel) else None
        self._layout = Layout(body)
        # (largest stretch, powers) of each pass over the springs of the step under way
        self._passes: list[tuple[float, dict[str, float]]] | None = None

    @property
    def kernel(self) -> str:
        """Name of the spring kernel in use, "numba" or "numpy"."""
        return self.springs.name

    @property
    def layout(self) -> Layout:
        """The body as the arrays a backend reads, laid out again only after an edit."""
        if self._layout.version != self.body.version:
            self._layout = Layout(self.body)
        return self._layout

    @property
    def masses(self) -> np.ndarray:
        """Masses (N,) in kg."""
        return self.body.masses

    @property
    def free(self) -> np.ndarray:
        """True for particles that may move (N,)."""
        return ~self.body.fixed

    def step(self, integrator: Integrator, x: np.ndarray, v: np.ndarray, dt: float) -> Step:
        """One step of ``integrator`` from positions ``x`` and velocities ``v`` (N, d): its new
        state as float arrays of the step's own (those the backend's `advance` made, copies
        of any other), the fixed particles kept where they were, at rest; with the largest
        stretch and the mechanisms' powers of its passes over the springs (`Step`).

        While a debugger traces the program, a dynamics that was asked for no kernel steps on
        the readable one (`stepping_backend`)."""
        if self.readable is not None:
            self.springs = stepping_backend(self.chosen, self.readable)
        self._passes = passes = []
        try:
            result = integrator.step(x, v, dt, self)
        finally:
            self._passes = None
        try:
            x_new, v_new = result
        except (TypeError, ValueError):
            raise TypeError(
                f"{integrator!r}.step must return (x_new, v_new), got {type(result).__name__}"
            ) from None
        x_new, v_new = np.asarray(x_new, dtype=float), np.asarray(v_new, dtype=float)
        for name, array in (("x_new", x_new), ("v_new", v_new)):
            if array.shape != x.shape:
                raise ValueError(
                    f"{integrator!r}.step returned {name} of shape {array.shape}; "
                    f"it must have the shape of the positions, {x.shape}"
                )
        if type(result) is not Made:  # the integrator's own arrays, or its arithmetic's
            x_new, v_new = x_new.copy(), v_new.copy()
        fixed = self.body.fixed
        if np.count_nonzero(fixed):  # faster than fixed.any() on a few rows
            pinned = np.flatnonzero(fixed)  # indices: a mask costs 68 µs on 16 384 rows
            x_new[pinned] = x[pinned]
            v_new[pinned] = 0.0
        stretch = 0.0
        for pass_stretch, _ in passes:
            stretch = max(stretch, pass_stretch)
        return Step(x_new, v_new, stretch, passes[0][1] if passes else None)

    def force(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Total force on each particle (N, d) in N."""
        return self._force(x, v)[0]

    def powers(self, x: np.ndarray, v: np.ndarray) -> dict[str, float]:
        """The power (W) each mechanism takes out at (x, v), by ledger name: the dashpots'
        ("dashpot") and each force's, from a pass over the springs."""
        return self._force(x, v)[1]

    def _force(self, x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, dict[str, float]]:
        """`force` and `powers` from one pass."""
        total = np.zeros_like(x)
        sums = self.springs.spring_forces(self.layout, x, v, total)
        powers = {"dashpot": sums.power}
        for force in self.forces:
            _count(powers, force.ledger_name, force.add_to(self.body, x, v, total))
        if self._passes is not None:
            self._passes.append((sums.stretch, powers))
        return total, powers

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

        Within a `step`, its pass is one of the step's: its largest stretch and the power
        each mechanism takes out (the dashpots' from the backend's pass over the springs,
        each force's from its `Force.add_to`) go to the step's `Step`.
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
        layout = self._layout if self._layout.version == self.body.version else self.layout
        step = self.springs.advance(update, layout, x, v, field, dt, coefficients, others)
        if self._passes is not None:
            powers["dashpot"] = step.power
            self._passes.append((step.stretch, powers))
        return Made((step.x, step.v))

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
        self.springs.spring_forces(self.layout, x, v, total, springs)
        for force in self.forces:
            force.add_to(self.body, x, v, total)
        masses, free = self.body.masses[particles, None], ~self.body.fixed[particles, None]
        return equations.acceleration(total[particles], masses, free)

    def jacobians(self, x: np.ndarray, v: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v, sparse (N·d × N·d), for implicit integrators.

        The sparsity pattern of the springs is built once per edit (`Layout.pattern`).
        """
        jx, jv = self.springs.jacobians(self.layout, x)
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
        layout = self.layout
        jx, jv = self.springs.jacobians(layout, x)
        values = -h_x * jx.data
        if jv.nnz:  # dashpots: on the same pattern
            values -= h_v * jv.data
        values[layout.pattern.diagonal] += np.repeat(self.masses, x.shape[1])
        matrix = layout.pattern.matrix(values)
        for force in self.forces:
            fx, fv = force.jacobians(self.body, x, v)
            jx = jx if fx is None else jx + fx
            matrix = matrix if fx is None else matrix - h_x * fx
            matrix = matrix if fv is None else matrix - h_v * fv
        return matrix, jx

    def elastic_energy(self, x: np.ndarray, springs: np.ndarray | None = None) -> float:
        """Energy stored in the springs (or in the given ones), Σ ½ k (|x_a - x_b| - l)² (J)."""
        return self.springs.elastic_energy(self.layout, x, springs)

    def potential_energy(self, x: np.ndarray) -> float:
        """Elastic energy of the springs plus the potential of the forces (J)."""
        return self.elastic_energy(x) + sum(
            force.potential_energy(self.body, x) for force in self.forces
        )


def _count(powers: dict[str, float], name: str, power: float | None) -> None:
    """Add ``power`` (W; None or 0 for a conservative force) to ``powers[name]``."""
    if power:
        powers[name] = powers.get(name, 0.0) + power
