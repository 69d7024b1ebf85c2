"""The backend contract: what `Dynamics`, `Simulation` and `Ground` need from a backend.

A backend computes, for all springs of a body at once, what `Spring.force` computes for
one (eq. 1.1-1.2 with the dashpot), their energy and Jacobians, and steps the particles
with an integrator's update; it also checks the state, sums the work of an integrator's
velocity factor and clamps particles to the ground, booking the energy that takes out.
`SpringKernel` is the whole contract, seven methods, none optional; nothing else asks a
backend for more, and nothing asks which one runs: `numpy.NumpyKernel` (readable, whole
arrays, the reference every backend is tested against) or `numba.NumbaKernel` (compiled
loops, the default). Both apply the same `msdlab.engine.equations`.

A backend is given what it reads as values: the body laid out as arrays once per edit
(`layout.Layout`), the state (x, v) at every call; it returns values (`SpringSums`,
`Jacobians`, `Advanced`: the new state as arrays no one else holds, which the
simulation hands back at the next step), and sets nothing for another class to read.
`choice` picks the backend.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple, Protocol

import numpy as np
import scipy.sparse as sp

from .layout import Layout


class SpringSums(NamedTuple):
    """What a pass over the springs finds besides their forces."""

    stretch: float  # the largest |x_a - x_b| / l, to detect blow-ups (dimensionless)
    power: float  # Σ c ((v_a - v_b)·n)², the power the dashpots take out (W), >= 0


class Jacobians(NamedTuple):
    """The springs' ∂F/∂x (N/m) and ∂F/∂v (N·s/m), sparse (N·d × N·d)."""

    position: sp.csr_matrix
    velocity: sp.csr_matrix


class Advanced(NamedTuple):
    """One step of an integrator's update, and the `SpringSums` of the pass it took."""

    x: np.ndarray  # positions (N, d) in m
    v: np.ndarray  # velocities (N, d) in m/s
    stretch: float
    power: float


# An integrator's update ``update(x, v, a, dt, *coefficients) -> (x_new, v_new)``, a function
# of numbers or whole arrays (like `integrators.Verlet.update`).
Update = Callable[..., tuple[np.ndarray, np.ndarray]]


class SpringKernel(Protocol):
    """What a backend provides; `NumpyKernel` and `NumbaKernel` have all of it.

    ``layout`` is the body's springs, masses and fixed particles as arrays (`Layout`, laid
    out once per edit of the body: a backend never reads a `Body`), ``x`` and ``v`` are
    positions (m) and velocities (m/s), (N, d) float64 with d = 2 or 3. ``springs``
    (indices) restricts a method to some springs.
    """

    name: str

    def spring_forces(
        self,
        layout: Layout,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> SpringSums:
        """Add the spring and dashpot forces (N), eq. (1.1)-(1.2), to ``out`` (N, d); with the
        largest stretch and the dashpots' power (W) of the same pass."""

    def elastic_energy(
        self, layout: Layout, x: np.ndarray, springs: np.ndarray | None = None
    ) -> float:
        """Energy (J) stored in the springs, Σ ½ k (|x_a - x_b| - l)²."""

    def jacobians(self, layout: Layout, x: np.ndarray) -> Jacobians:
        """∂F/∂x and ∂F/∂v of the springs on the layout's pattern (`Layout.pattern`; see
        `backends.numpy.spring_jacobians`)."""

    def finite(self, x: np.ndarray, v: np.ndarray) -> bool:
        """Whether every position and velocity (N, d) is a finite number."""

    def advance(
        self,
        update: Update,
        layout: Layout,
        x: np.ndarray,
        v: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        forces: np.ndarray | None = None,
    ) -> Advanced:
        """``update(x, v, a, dt, *coefficients)`` with a = (F + m·g)/m, 0 for fixed particles.

        F is the spring forces plus ``forces`` (N, d) in N, the other forces, if given;
        g = ``field`` (d,) in m/s². The numpy backend does it in a few lines on arrays;
        the numba backend runs the springs' pass, a and the update in compiled loops. The new
        x and v are arrays no one else holds (the simulation keeps them as the state).
        """

    def damping_work(
        self, masses: np.ndarray, v_before: np.ndarray, v_after: np.ndarray, factor: float
    ) -> float:
        """`equations.damping_work` (J): the work of an integrator's velocity factor per step,
        which the ledger books for an integrator that does not book its own."""

    def ground_clamp(
        self,
        x: np.ndarray,
        v: np.ndarray,
        x_old: np.ndarray,
        v_old: np.ndarray,
        masses: np.ndarray,
        fixed: np.ndarray,
        normal: np.ndarray,
        height: float,
        dt: float,
        friction: float,
    ) -> float:
        """`interaction.Ground`: the free particles below the plane put back on it, in place
        (`backends.numpy.ground_clamp`); the energy (J) the ground removed."""
