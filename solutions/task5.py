"""Task 5: Verlet integration with damping, eq. (1.3) and (1.4).

Write the time integration of the brief as an engine integrator::

    x(t + dt) = (2 - λ)·x(t) - (1 - λ)·x(t - dt) + a(t)·dt²        (1.4)

λ = 0 is eq. (1.3), which the template's kernel already is (task 1), so the
template's trajectories must come out exactly. Then answer: does damping change
the behaviour (it takes energy out), and does it allow larger time steps?
Measure the largest stable dt (`measured_stable_dt`) and compare it with the
engine's prediction for your integrator (``msd.max_stable_dt``).
``msdlab check 5`` grades it.

Like the template, the integrator keeps three positions: the previous one,
x(t - dt), is not stored but recovered as x - v·dt from the velocity v that
the previous step returned, v = (x(t + dt) - x(t))/dt. The engine's floor
(``msd.Ground``) edits x and v after each step, and the next step sees it.
"""

from __future__ import annotations

import numpy as np

import msdlab as msd

N = 3  # particles per edge of the jelly used by `measured_stable_dt`
STIFFNESS = 0.5


# --------------------------------------------------------------------------- given code
def jelly(n: int = N) -> msd.Body:
    """An n³ jelly cube: spacing 2/n, stiffness STIFFNESS, neighbours at 1, √2 and √3 spacings."""
    return msd.Body.grid((n, n, n), spacing=2.0 / n, stiffness=STIFFNESS, neighbours=(1, 2, 3))


# --------------------------------------------------------------------------- your answers
class DampedVerlet(msd.Integrator):
    """Position Verlet with damping λ in [0, 1), eq. (1.4); λ = 0 is eq. (1.3), the template."""

    order = 2

    def __init__(self, damping: float = 0.0) -> None:
        """Store the damping λ; raise ValueError unless 0 <= λ < 1 (λ >= 1 flips the motion)."""
        ### BEGIN SOLUTION
        # TODO: check that 0 <= damping < 1 (else raise ValueError) and store it as self.damping.
        lam = float(damping)
        if not 0.0 <= lam < 1.0:
            raise ValueError(
                f"damping λ must be in [0, 1), got {lam}: λ = 0 is no damping, and "
                "λ >= 1 would flip or freeze the velocity every step"
            )
        self.damping = lam
        ### END SOLUTION

    def step(
        self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: msd.Dynamics
    ) -> tuple[np.ndarray, np.ndarray]:
        """One step of eq. (1.4): returns (x(t + dt), v) with v = (x(t + dt) - x(t))/dt.

        ``x``, ``v`` (N, d): positions x(t) and the velocity the previous step
        returned, so x(t - dt) = x - v·dt; a(t) = ``dynamics.acceleration(x, v)``.
        New arrays are returned; ``x`` and ``v`` are not modified.
        """
        ### BEGIN SOLUTION
        # TODO: recover x(t - dt), apply eq. (1.4), return the new positions and velocities.
        lam = self.damping
        old, current = x - v * dt, x  # x(t - dt) and x(t): the template's old and current
        acceleration = dynamics.acceleration(current, v)
        new = (2.0 - lam) * current - (1.0 - lam) * old + acceleration * dt**2
        return new, (new - current) / dt
        ### END SOLUTION


def measured_stable_dt(damping: float, n: int = N, steps: int = 1000, rtol: float = 1e-3) -> float:
    """Largest dt (s) for which `DampedVerlet` (damping λ) keeps the jelly(n) stable, measured.

    Use ``msd.measure_blowup_dt(body, integrator, steps=steps, rtol=rtol)``: it
    bisects dt, running ``steps`` steps from a small random kick each time.
    Compare with ``msd.max_stable_dt(body, DampedVerlet(damping))``, the
    prediction √(4 - 2λ)/ω for the stiffest mode ω. Larger with damping?
    """
    ### BEGIN SOLUTION
    # TODO: measure the blow-up dt of the jelly with DampedVerlet(damping).
    return msd.measure_blowup_dt(jelly(n), DampedVerlet(damping), steps=steps, rtol=rtol)
    ### END SOLUTION
