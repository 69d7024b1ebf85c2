"""Task 5 written differently: eq. (1.4) rearranged as x + (1 - λ)(x - x_old) + a dt²."""

from __future__ import annotations

import math

import msdlab as msd


class DampedVerlet(msd.Integrator):
    def __init__(self, damping=0.0):
        if math.isnan(damping) or damping < 0 or damping >= 1:
            raise ValueError("damping must be in [0, 1)")
        self.keep = 1.0 - damping

    def step(self, x, v, dt, dynamics):
        displacement = self.keep * v * dt + dynamics.acceleration(x, v) * dt * dt
        return x + displacement, displacement / dt


def measured_stable_dt(damping, n=3, steps=1000, rtol=1e-3):
    body = msd.Body.grid((n, n, n), spacing=2.0 / n, stiffness=0.5, neighbours=(1, 2, 3))
    predicted = msd.max_stable_dt(body, DampedVerlet(damping))
    return msd.measure_blowup_dt(
        body, DampedVerlet(damping), steps=steps, rtol=rtol, low=predicted / 3, high=2 * predicted
    )
