"""Task 1 written a fourth way: plain Python, a doubling and bisecting search."""

from __future__ import annotations

import numpy as np


def particle_count(n=20):
    per_edge = int(n)
    return per_edge * per_edge * per_edge


def integration_scheme():
    return SCHEMES[2]


def verlet_step(old, current, dt, acceleration):
    a = np.array(acceleration, dtype=float)
    return np.add(np.subtract(2 * current, old), a * (dt * dt))


def height_after(steps, y0=1.5, dt=0.1, g=-0.001):
    drop = 0.0
    for k in range(1, steps + 1):
        drop += k * g * dt * dt
    return y0 + drop


def steps_to_floor(y0=1.5, dt=0.1, g=-0.001):
    if y0 <= 0:
        raise ValueError("the particle must start above the floor")
    if g >= 0 or dt <= 0:
        raise ValueError("it must fall (g < 0) with a positive time step")
    low, high = 0, 1
    while height_after(high, y0, dt, g) > 0:
        low, high = high, 2 * high
    while high - low > 1:
        middle = (low + high) // 2
        if height_after(middle, y0, dt, g) > 0:
            low = middle
        else:
            high = middle
    return high
