"""Task 1 written a second way: numpy's own sums and the quadratic's root."""

from __future__ import annotations

import numpy as np


def particle_count(n=20):
    return int(np.prod(np.full(3, n, dtype=np.int64)))


def integration_scheme():
    return "position verlet"


def verlet_step(old, current, dt, acceleration):
    old, current = np.asarray(old, float), np.asarray(current, float)
    return current + (current - old) + np.asarray(acceleration, float) * dt**2


def height_after(steps, y0=1.5, dt=0.1, g=-0.001):
    return y0 + g * dt * dt * float(np.arange(1, steps + 1).sum())


def steps_to_floor(y0=1.5, dt=0.1, g=-0.001):
    if y0 <= 0 or dt <= 0 or g >= 0:
        raise ValueError(f"a particle must start above the floor and fall: y0={y0}, g={g}")
    fall = -g * dt * dt  # the drop of the first step; the n-th drops n times as far
    n = int(np.ceil((np.sqrt(1.0 + 8.0 * y0 / fall) - 1.0) / 2.0))
    while y0 - fall * n * (n + 1) / 2 > 0:
        n += 1
    while n > 0 and y0 - fall * (n - 1) * n / 2 <= 0:
        n -= 1
    return n
