"""Task 5 written a second way: the step from the previous position it recovers."""

from __future__ import annotations

import msdlab as msd


class DampedVerlet(msd.Integrator):
    order = 2

    def __init__(self, damping=0.0):
        if not (0.0 <= damping < 1.0):
            raise ValueError(f"damping must lie in [0, 1), got {damping}")
        self.damping = float(damping)

    def step(self, x, v, dt, dynamics):
        previous = x - dt * v
        a = dynamics.acceleration(x, v)
        following = x + (1.0 - self.damping) * (x - previous) + dt * dt * a
        return following, (following - x) / dt


def measured_stable_dt(damping, n=3, steps=1000, rtol=1e-3):
    return msd.measure_blowup_dt(jelly(n), DampedVerlet(damping), steps=steps, rtol=rtol)
