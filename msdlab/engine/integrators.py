"""Time integrators: each advances positions x (N, d) and velocities v (N, d) by dt.

An integrator only needs ``dynamics.acceleration(x, v)`` (see `Dynamics`); it
returns the new (x, v) and does not touch the body, so every scheme here is a
few lines that read like its formula. The `Simulation` calls the integrator's
`step` every step, then pins fixed particles and applies the constraints
(ground, drag, ...).

A scheme that needs a(x, v) once, at the current state, writes its equation as
a plain function of numbers ``update(x, v, a, dt, *coefficients) -> (x_new, v_new)``
(like `Verlet.update`) and steps with ``dynamics.advance(update, x, v, dt, *coefficients)``.
On whole arrays that is ``update(x, v, dynamics.acceleration(x, v), dt, ...)``;
the numba kernel compiles the same function into one loop with a = F/m, for
any integrator, the engine's or a user's. A scheme that takes energy out
on purpose by scaling the velocity (Verlet's λ) states its `velocity_factor`,
and the ledger books that work.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from functools import cache
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from threadpoolctl import ThreadpoolController

from .dynamics import Dynamics
from .equations import damping_work, kinetic_energy

if TYPE_CHECKING:
    from .backends.contract import SpringKernel, Update

State = tuple[np.ndarray, np.ndarray]


class Integrator(ABC):
    """A time-stepping scheme. Subclasses implement `step`."""

    order = 1  # global order of accuracy in dt for smooth problems

    @abstractmethod
    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        """Return (x, v) one step of ``dt`` seconds later."""

    @property
    def velocity_factor(self) -> float:
        """The factor the scheme scales the velocity it starts a step from by, before the
        forces act (damped Verlet, eq. 1.4: 1 - λ); 1 for none."""
        return 1.0

    def dissipated_energy(
        self,
        v: np.ndarray,
        masses: np.ndarray,
        v_new: np.ndarray | None = None,
        *,
        kernel: SpringKernel | None = None,
    ) -> float:
        """Energy (J) the scheme removes on purpose in the step from velocities ``v`` to
        ``v_new``, which the energy ledger books every step.

        Here: the work of the kick (factor - 1)·v of `velocity_factor`, summed by the
        ``kernel`` that steps the body (`SpringKernel.damping_work`; the simulation passes
        its own, None is `equations.damping_work`), or (1 - factor²)·½ Σ m v² when ``v_new``
        is not given; 0 for a factor of 1. A scheme that takes energy out another way
        overrides this method, keeping its parameters (it may ignore ``kernel``).
        """
        factor = self.velocity_factor
        if factor == 1.0:
            return 0.0
        if v_new is None:
            return float((1.0 - factor**2) * kinetic_energy(masses, v))
        work = damping_work if kernel is None else kernel.damping_work
        return work(masses, v, v_new, factor)

    def update_step(self) -> tuple[Update, tuple[float, ...]] | None:
        """``(update, coefficients)`` if `step` is ``dynamics.advance(update, x, v, dt,
        *coefficients)`` and nothing else, so a device backend may run whole steps itself
        (`Simulation`); None here (a step the backend cannot see into)."""
        return None

    def velocity_at_positions(self, v: np.ndarray, a: np.ndarray, dt: float) -> np.ndarray:
        """The velocity at the time of the positions, for energy measurements; ``v`` here.

        ``v`` is the velocity the scheme stores and ``a`` the acceleration now.
        """
        return v

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class ExplicitEuler(Integrator):
    """Forward Euler: x += dt·v and v += dt·a, both from the old state. Order 1.

    Its energy grows every step for any dt on undamped springs (it is unstable
    without damping); it is here to show why better schemes exist.
    """

    @staticmethod
    def update(x: float, v: float, a: float, dt: float) -> tuple[float, float]:
        """x + dt·v and v + dt·a, both from the old state (numbers or arrays)."""
        return x + dt * v, v + dt * a

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        """`update` with a = F(x, v)/m (`Dynamics.advance`)."""
        return dynamics.advance(self.update, x, v, dt)

    def update_step(self) -> tuple[Update, tuple[float, ...]] | None:
        """`update` with no coefficients, unless a subclass steps its own way."""
        return (self.update, ()) if type(self).step is ExplicitEuler.step else None


class SymplecticEuler(Integrator):
    """Semi-implicit Euler: v += dt·a(x), then x += dt·v with the new v. Order 1.

    Symplectic: energy stays bounded for dt below 2/ω of the stiffest mode.
    """

    @staticmethod
    def update(x: float, v: float, a: float, dt: float) -> tuple[float, float]:
        """v_new = v + dt·a, then x + dt·v_new (numbers or arrays)."""
        v_new = v + dt * a
        return x + dt * v_new, v_new

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        """`update` with a = F(x, v)/m (`Dynamics.advance`)."""
        return dynamics.advance(self.update, x, v, dt)

    def update_step(self) -> tuple[Update, tuple[float, ...]] | None:
        """`update` with no coefficients, unless a subclass steps its own way."""
        return (self.update, ()) if type(self).step is SymplecticEuler.step else None


class Verlet(Integrator):
    """Position Verlet of the brief, eq. (1.3), with damping λ, eq. (1.4)::

        x(t+dt) = (2 - λ) x(t) - (1 - λ) x(t-dt) + a(t) dt²

    Like the template it keeps three position buffers: old x(t-dt), current
    x(t) and new x(t+dt). The old one is ``x - v·dt``, where ``v`` is what the
    previous step stored, (new - current)/dt: exactly the template's
    ``v = (cur - old)/dt``. So λ = 0 reproduces the template's ``msd_kernel``,
    and edits of the velocities (drag, ground, dragging) are seen by the next step.

    Started like the template (old = x - v·dt at t = 0) the scheme is globally
    first order when the initial acceleration is not zero: the start misses the
    ½·a·dt² term. A Taylor start would restore order 2 but break the
    equivalence with the template. Stable for dt < √(4 - 2λ)/ω.
    """

    order = 2

    def __init__(self, damping: float = 0.0) -> None:
        damping = float(damping)
        if not 0.0 <= damping < 1.0:
            raise ValueError(
                f"Verlet damping λ must be in [0, 1), got {damping}: λ = 0 is no damping, "
                "λ -> 1 stops all motion, λ >= 1 flips or freezes the velocity term every step"
            )
        self.damping = damping

    @staticmethod
    def update(x: float, v: float, a: float, dt: float, damping: float) -> tuple[float, float]:
        """Eq. (1.4) from x(t), the stored v and a(t), with damping λ (numbers or arrays)."""
        old = x - v * dt  # x(t - dt), the template's old buffer
        new = (2.0 - damping) * x - (1.0 - damping) * old + a * dt**2  # eq. (1.4)
        return new, (new - x) / dt

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        """x(t + dt) and v by eq. (1.4), `update`, with a(t) = F(x, v)/m: `Dynamics.advance`
        computes a and applies the equation (on the numba kernel, in one compiled loop)."""
        return dynamics.advance(self.update, x, v, dt, self.damping)

    def update_step(self) -> tuple[Update, tuple[float, ...]] | None:
        """`update` with the damping λ, unless a subclass steps its own way."""
        return (self.update, (self.damping,)) if type(self).step is Verlet.step else None

    def velocity_at_positions(self, v: np.ndarray, a: np.ndarray, dt: float) -> np.ndarray:
        """v(t) ≈ v(t - dt/2) + ½ a(t) dt: the stored velocity is half a step behind x."""
        return v + 0.5 * dt * a

    @property
    def velocity_factor(self) -> float:
        """1 - λ: the damping's kick -λ·v takes out energy (`Integrator.dissipated_energy`)."""
        return 1.0 - self.damping

    def __repr__(self) -> str:
        return f"Verlet(damping={self.damping:g})"


class VelocityVerlet(Integrator):
    """Velocity Verlet (leapfrog): half kick, drift, half kick. Order 2, symplectic.

    The second kick needs a(x_new, v_new); for velocity-dependent forces
    (dashpots) it uses the predictor v + dt·a, which keeps the scheme second order.
    """

    order = 2

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        a = dynamics.acceleration(x, v)
        v_half = v + 0.5 * dt * a
        x_new = x + dt * v_half
        return x_new, v_half + 0.5 * dt * dynamics.acceleration(x_new, v + dt * a)


class RK4(Integrator):
    """Classical fourth-order Runge-Kutta on the state (x, v). Order 4, not symplectic."""

    order = 4

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        a = dynamics.acceleration
        k1x, k1v = v, a(x, v)
        k2x, k2v = v + 0.5 * dt * k1v, a(x + 0.5 * dt * k1x, v + 0.5 * dt * k1v)
        k3x, k3v = v + 0.5 * dt * k2v, a(x + 0.5 * dt * k2x, v + 0.5 * dt * k2v)
        k4x, k4v = v + dt * k3v, a(x + dt * k3x, v + dt * k3v)
        x_new = x + dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x)
        return x_new, v + dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)


class ImplicitEuler(Integrator):
    """Linearised backward Euler (Baraff & Witkin 1998), one sparse solve per step::

        (M - dt ∂F/∂v - dt² ∂F/∂x) Δv = dt (F + dt ∂F/∂x v),   v += Δv,   x += dt v

    Stable far beyond the explicit limit, but order 1 and it damps energy
    numerically (the drift in the energy ledger). The system is symmetric
    positive definite and is solved by conjugate gradients over the free
    particles, with BLAS on one thread: its vectors are too short to share out,
    and BLAS threads waiting for work slowed a 20³ step 5-fold on 2 busy cores.
    """

    def __init__(self, tolerance: float = 1e-10) -> None:
        self.tolerance = float(tolerance)

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        dim = x.shape[1]
        matrix, jx = dynamics.implicit_matrix(x, v, dt, dt * dt)  # M - dt ∂F/∂v - dt² ∂F/∂x
        rhs = dt * (dynamics.force(x, v).ravel() + dt * (jx @ v.ravel()))
        free = np.repeat(dynamics.free, dim)
        with _thread_pools().limit(limits=1, user_api="blas"):
            dv = _solve_spd(matrix, rhs, free, self.tolerance)
        v_new = v + dv.reshape(v.shape)
        return x + dt * v_new, v_new

    def __repr__(self) -> str:
        return f"ImplicitEuler(tolerance={self.tolerance:g})"


@cache
def _thread_pools() -> ThreadpoolController:
    """The thread pools of the loaded native libraries (BLAS, OpenMP), found once."""
    return ThreadpoolController()


def _solve_spd(
    matrix: sp.csr_matrix, rhs: np.ndarray, free: np.ndarray, tolerance: float
) -> np.ndarray:
    """Solve matrix·u = rhs for the ``free`` entries of u, the others being 0.

    The rows and columns of the other entries are replaced by the identity in
    place (the sparsity stays), then Jacobi-preconditioned CG solves, or a
    direct solve if CG stalls.
    """
    import scipy.sparse.linalg as spla  # imported here: scipy.linalg with it, 0.3 s

    if rhs.size == 0:
        return rhs
    if not free.all():
        rows = np.repeat(np.arange(len(free)), np.diff(matrix.indptr))
        pinned = ~free[rows] | ~free[matrix.indices]
        matrix.data[pinned] = rows[pinned] == matrix.indices[pinned]
        rhs = np.where(free, rhs, 0.0)
    jacobi = sp.diags(1.0 / matrix.diagonal())
    solution, info = spla.cg(matrix, rhs, rtol=tolerance, atol=0.0, M=jacobi, maxiter=10 * rhs.size)
    if info != 0:
        solution = spla.spsolve(matrix.tocsc(), rhs)
    return solution
