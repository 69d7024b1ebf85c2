"""Verlet(damping=0) reproduces the brief's template kernel, floor included."""

import numpy as np

import msdlab as msd
from msdlab.engine.backends import numpy as numpy_backend

N, DT = 6, 0.1
GRAVITY = np.array([0.0, -0.001, 0.0])


def template_start(n: int) -> np.ndarray:
    """The template's initial positions: coord / N * 2 - 1 + (0, 2.5, 0)."""
    coord = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    return coord / n * 2 - 1 + np.array([0.0, 2.5, 0.0])


def msd_kernel(old, cur, acceleration, dt):
    """The template's per-particle update, literally: returns the new buffer."""
    v = (cur - old) / dt
    v += dt * acceleration
    new = cur + dt * v
    new[:, 1] = np.where(new[:, 1] < 0, 0.0, new[:, 1])
    return new


def test_falling_grid_matches_template_step_by_step():
    cur = template_start(N)
    old = cur.copy()  # zero initial velocity
    body = msd.Body.grid((N, N, N), spacing=2 / N, neighbours=(), origin=(-1, 1.5, -1))
    np.testing.assert_allclose(body.positions, cur, atol=1e-15)
    sim = msd.Simulation(body, msd.Verlet(), DT, [msd.Gravity(GRAVITY), msd.Ground(0.0)])
    worst = 0.0
    for _ in range(800):  # the bottom layer lands in step 548
        old, cur = cur, msd_kernel(old, cur, GRAVITY, DT)
        sim.step()
        worst = max(worst, np.max(np.abs(body.positions - cur)))
    assert cur[:, 1].min() == 0.0  # the floor was reached
    assert worst < 1e-13


def test_free_fall_height_follows_the_discrete_formula():
    """After n steps from rest: y = y0 + a dt² n(n+1)/2 (the template's scheme)."""
    body = msd.Body.grid((2, 2, 2), spacing=1.0, neighbours=(), origin=(0, 100.0, 0))
    sim = msd.Simulation(body, msd.Verlet(), DT, [msd.Gravity(GRAVITY)])
    n = 300
    sim.run(steps=n)
    expected = 100.0 + GRAVITY[1] * DT**2 * n * (n + 1) / 2
    np.testing.assert_allclose(body.positions[0, 1], expected, rtol=1e-11)  # rounding only


def test_springy_grid_matches_template_with_spring_acceleration():
    """The template extended with eq. (1.1)-(1.2) (unit mass) against Verlet + body springs."""
    body = msd.Body.grid(
        (4, 4, 4), spacing=0.5, stiffness=0.5, neighbours=(1, 2, 3), origin=(-1, 1.5, -1)
    )
    body.rotate(msd.rotation_matrix(58.3, axis=(0, 0, 1)))
    cur = body.positions.copy()
    old = cur.copy()
    sim = msd.Simulation(body, msd.Verlet(), 0.4, [msd.Gravity(GRAVITY), msd.Ground(0.0)])
    zero = np.zeros_like(cur)
    landed = False
    for _ in range(400):
        acceleration = GRAVITY + numpy_backend.spring_forces(body, cur, zero)[0]
        old, cur = cur, msd_kernel(old, cur, acceleration, 0.4)
        sim.step()
        landed |= cur[:, 1].min() == 0.0
    assert landed
    np.testing.assert_allclose(body.positions, cur, atol=1e-11)
