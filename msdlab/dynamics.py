"""Dynamics: the equations of motion of a body, a = F(x, v) / m."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from . import kernels
from .body import Body
from .forces import Force


class Dynamics:
    """Newton's second law for a body: a_i = F_i / m_i, eq. (1.1) with masses.

    F is the sum of the spring and dashpot forces (eq. 1.2, `kernels.spring_forces`)
    and the external ``forces``. Fixed particles have zero inverse mass, so they
    get zero acceleration. Integrators only call `acceleration` (and `force`,
    `jacobians`, `masses`, `free` for implicit methods).
    """

    def __init__(self, body: Body, forces: Sequence[Force] = ()) -> None:
        self.body = body
        self.forces = list(forces)
        self.max_stretch = 0.0  # largest |d|/l seen in the last force evaluation

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
        total, self.max_stretch = kernels.spring_forces(self.body, x, v)
        for force in self.forces:
            force.add_to(self.body, x, v, total)
        return total

    def acceleration(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Acceleration of each particle (N, d) in m/s²; zero for fixed particles."""
        inverse_mass = np.where(self.body.fixed, 0.0, 1.0 / self.body.masses)
        return self.force(x, v) * inverse_mass[:, None]

    def acceleration_of(self, particles: np.ndarray, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Acceleration (M, d) of some particles only, from the springs touching them."""
        total, _ = kernels.spring_forces(
            self.body, x, v, springs=self.body.springs_touching(particles)
        )
        for force in self.forces:
            force.add_to(self.body, x, v, total)
        free = ~self.body.fixed[particles]
        return total[particles] * (free / self.body.masses[particles])[:, None]

    def jacobians(self, x: np.ndarray, v: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v, sparse (N·d × N·d), for implicit integrators."""
        jx, jv = kernels.spring_jacobians(self.body, x)
        for force in self.forces:
            fx, fv = force.jacobians(self.body, x, v)
            jx = jx if fx is None else jx + fx
            jv = jv if fv is None else jv + fv
        return jx, jv

    def potential_energy(self, x: np.ndarray) -> float:
        """Elastic energy of the springs plus the potential of the forces (J)."""
        return kernels.elastic_energy(self.body, x) + sum(
            force.potential_energy(self.body, x) for force in self.forces
        )
