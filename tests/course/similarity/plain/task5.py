"""Task 5 written a fourth way: eq. (1.4) in velocity form, v' = (1 - λ)v + a·dt."""

from __future__ import annotations

import msdlab as msd


class DampedVerlet(msd.Integrator):
    order = 2

    def __init__(self, damping=0.0):
        value = float(damping)
        if value != value or value < 0 or value >= 1:
            raise ValueError("the damping must be at least 0 and below 1")
        self.damping = value

    def step(self, x, v, dt, dynamics):
        v_new = (1 - self.damping) * v + dt * dynamics.acceleration(x, v)
        return x + dt * v_new, v_new


def measured_stable_dt(damping, n=3, steps=1000, rtol=1e-3):
    cube = jelly(n)
    integrator = DampedVerlet(damping)
    return msd.measure_blowup_dt(cube, integrator, steps=steps, rtol=rtol)
