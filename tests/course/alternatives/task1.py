"""Task 1 answered differently from the reference: loops instead of closed forms."""

from __future__ import annotations

import numpy as np

N = 20
DT = 0.1
GRAVITY = (0.0, -0.001, 0.0)


def particle_count(n: int = N) -> int:
    count = 0
    for _ in range(n):
        count += n * n
    return count


def integration_scheme() -> str:
    return "Symplectic Euler "  # the same positions as position Verlet (eq. 1.3)


def verlet_step(old, current, dt, acceleration):
    velocity = current - old
    return current + velocity + np.multiply(acceleration, dt * dt)


def height_after(steps, y0=1.5, dt=DT, g=GRAVITY[1]):
    y, v = y0, 0.0
    for _ in range(steps):
        v += g * dt
        y += v * dt
    return y


def steps_to_floor(y0=1.5, dt=DT, g=GRAVITY[1]):
    if y0 <= 0 or g >= 0 or dt <= 0:
        raise ValueError("the particle must start above the floor and fall, with dt > 0")
    steps, y_old, y = 0, y0, y0
    while y > 0:
        y_old, y = y, 2 * y - y_old + g * dt * dt
        steps += 1
    return steps
