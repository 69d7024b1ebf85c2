"""Dynamics: the equations of motion of a body, a = F(x, v) / m."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from . import kernels
from .body import Body
from .forces import Force

KERNELS = ("numba", "numpy")


def default_kernel() -> str:
    """The spring kernel to use: ``MSDLAB_KERNEL`` if set, else "numba" when it is installed.

    "numba" is the compiled loop of `msdlab.compiled`; "numpy" is the readable
    array version of `msdlab.kernels`. Both compute the same forces.
    """
    name = os.environ.get("MSDLAB_KERNEL", "").strip().lower()
    if name:
        return _checked_kernel(name, "MSDLAB_KERNEL")
    try:
        import numba  # noqa: F401
    except ImportError:
        return "numpy"
    return "numba"


def _checked_kernel(name: str, what: str) -> str:
    if name not in KERNELS:
        raise ValueError(f"{what} must be one of {', '.join(KERNELS)}, got {name!r}")
    return name


class Dynamics:
    """Newton's second law for a body: a_i = F_i / m_i, eq. (1.1) with masses.

    F is the sum of the spring and dashpot forces (eq. 1.2, `kernels.spring_forces`)
    and the external ``forces``. Fixed particles have zero inverse mass, so they
    get zero acceleration. Integrators only call `acceleration` (and `force`,
    `jacobians`, `masses`, `free` for implicit methods).

    ``kernel`` picks how the spring forces are computed: "numba" (compiled,
    threaded) or "numpy" (readable); the default is `default_kernel()`.
    """

    def __init__(self, body: Body, forces: Sequence[Force] = (), kernel: str | None = None) -> None:
        self.body = body
        self.forces = list(forces)
        self.kernel = default_kernel() if kernel is None else _checked_kernel(kernel, "kernel")
        self._compiled = None
        if self.kernel == "numba":
            from .compiled import CompiledKernels

            self._compiled = CompiledKernels()
        self.max_stretch = 0.0  # largest |d|/l seen in the last force evaluation
        self._pattern: kernels.JacobianPattern | None = None
        self._forces: np.ndarray | None = None  # force buffer of `compiled_step`

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
        if self._compiled is None:
            _, self.max_stretch = kernels.spring_forces(self.body, x, v, out=total)
        else:
            self.max_stretch, _ = self._compiled.add_spring_forces(self.body, x, v, total)
        for force in self.forces:
            force.add_to(self.body, x, v, total)
        return total

    def acceleration(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Acceleration of each particle (N, d) in m/s²; zero for fixed particles."""
        if self._compiled is not None:
            total = self.force(x, v)
            self._compiled.divide_by_masses(self.body, total)
            return total
        inverse_mass = np.where(self.body.fixed, 0.0, 1.0 / self.body.masses)
        return self.force(x, v) * inverse_mass[:, None]

    def compiled_step(
        self, integrator: object, x: np.ndarray, v: np.ndarray, dt: float
    ) -> tuple[np.ndarray, np.ndarray, float] | None:
        """``integrator.step(x, v, dt, self)`` in compiled passes, or None if there is none.

        There is one for exactly `Verlet`, `SymplecticEuler` and `ExplicitEuler`
        with the "numba" kernel: the spring kernel, the forces, then one loop
        over the particles doing what the class's `step` does. Returns the new
        x and v (buffers reused at the next call) and the dashpot power (W) at (x, v).
        """
        if self._compiled is None or not self._compiled.has_update(integrator):
            return None
        if self._forces is None or self._forces.shape != x.shape:
            self._forces = np.empty_like(x)
        total = self._forces
        total.fill(0.0)
        self.max_stretch, power = self._compiled.add_spring_forces(self.body, x, v, total)
        for force in self.forces:
            force.add_to(self.body, x, v, total)
        x_new, v_new = self._compiled.update(self.body, integrator, x, v, total, dt)
        return x_new, v_new, power

    def dashpot_power(self, x: np.ndarray, v: np.ndarray) -> float:
        """Power (W) the spring dashpots take out of the body at (x, v), Σ c ((v_a - v_b)·n)²."""
        if self._compiled is None:
            return kernels.dashpot_power(self.body, x, v)
        return self._compiled.dashpot_power(self.body, x, v)

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
        if self._compiled is None:
            kernels.spring_forces(self.body, x, v, out=total, springs=springs)
        else:
            self._compiled.add_spring_forces(self.body, x, v, total, springs)
        for force in self.forces:
            force.add_to(self.body, x, v, total)
        free = ~self.body.fixed[particles]
        return total[particles] * (free / self.body.masses[particles])[:, None]

    def jacobians(self, x: np.ndarray, v: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v, sparse (N·d × N·d), for implicit integrators.

        The sparsity pattern of the springs is built once per topology and refilled.
        """
        if self._pattern is None or self._pattern.topology_version != self.body.topology_version:
            self._pattern = kernels.JacobianPattern(self.body)
        jx, jv = kernels.spring_jacobians(self.body, x, self._pattern)
        for force in self.forces:
            fx, fv = force.jacobians(self.body, x, v)
            jx = jx if fx is None else jx + fx
            jv = jv if fv is None else jv + fv
        return jx, jv

    def elastic_energy(self, x: np.ndarray, springs: np.ndarray | None = None) -> float:
        """Energy stored in the springs (or in the given ones), Σ ½ k (|x_a - x_b| - l)² (J)."""
        if self._compiled is None:
            return kernels.elastic_energy(self.body, x, springs)
        return self._compiled.elastic_energy(self.body, x, springs)

    def potential_energy(self, x: np.ndarray) -> float:
        """Elastic energy of the springs plus the potential of the forces (J)."""
        return self.elastic_energy(x) + sum(
            force.potential_energy(self.body, x) for force in self.forces
        )
