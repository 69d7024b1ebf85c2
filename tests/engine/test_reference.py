"""Small random systems against scipy's solve_ivp at tight tolerance; 2-D equals 3-D."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import msdlab as msd


def random_system(seed: int, dim: int) -> tuple[msd.Body, np.ndarray]:
    """4 particles, 5 springs (some stretched, some damped), one fixed, and gravity."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-1, 1, (4, dim)) + np.arange(4)[:, None]
    pairs = [[0, 1], [1, 2], [2, 3], [0, 2], [1, 3]]
    lengths = np.linalg.norm(x[[p[0] for p in pairs]] - x[[p[1] for p in pairs]], axis=1)
    body = msd.Body.from_arrays(
        x,
        pairs,
        velocities=rng.normal(0, 0.3, (4, dim)),
        masses=rng.uniform(0.5, 2.0, 4),
        fixed=[True, False, False, False],
        stiffness=rng.uniform(5, 20, 5),
        rest_lengths=lengths * rng.uniform(0.8, 1.2, 5),
        damping=rng.uniform(0, 0.5, 5),
    )
    gravity = np.zeros(dim)
    gravity[1] = -9.81
    return body, gravity


def reference(body: msd.Body, gravity: np.ndarray, duration: float) -> np.ndarray:
    dynamics = msd.Dynamics(body, [msd.Gravity(gravity)])
    shape = body.positions.shape

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        x, v = y[: y.size // 2].reshape(shape), y[y.size // 2 :].reshape(shape)
        return np.concatenate([v.ravel(), dynamics.acceleration(x, v).ravel()])

    y0 = np.concatenate([body.positions.ravel(), body.velocities.ravel()])
    solution = solve_ivp(rhs, (0, duration), y0, method="DOP853", rtol=1e-12, atol=1e-12)
    return solution.y[: y0.size // 2, -1].reshape(shape)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(
    "integrator, dt, tolerance",
    [
        (msd.RK4(), 1e-3, 1e-10),
        (msd.VelocityVerlet(), 5e-4, 3e-7),
        (msd.ImplicitEuler(), 5e-4, 5e-3),
    ],
    ids=["RK4", "VelocityVerlet", "ImplicitEuler"],
)
def test_agrees_with_solve_ivp(seed, integrator, dt, tolerance):
    body, gravity = random_system(seed, 3)
    expected = reference(body, gravity, 0.5)
    msd.Simulation(body, integrator, dt, [msd.Gravity(gravity)]).run(duration=0.5)
    assert np.max(np.abs(body.positions - expected)) < tolerance


@pytest.mark.parametrize("integrator, order", [(msd.VelocityVerlet(), 2), (msd.RK4(), 4)], ids=repr)
def test_order_holds_with_dashpots_fixed_particles_and_gravity(integrator, order):
    body, gravity = random_system(5, 3)
    expected = reference(body, gravity, 0.5)

    def solve(dt: float) -> np.ndarray:
        trial = body.copy()
        msd.Simulation(trial, integrator, dt, [msd.Gravity(gravity)]).run(duration=0.5)
        return trial.positions

    result = msd.convergence_order(solve, [1e-2, 5e-3, 2.5e-3], expected)
    assert result.order == pytest.approx(order, abs=0.2), str(result)


@pytest.mark.parametrize("integrator", [msd.Verlet(0.1), msd.RK4(), msd.ImplicitEuler()], ids=repr)
def test_a_planar_body_moves_the_same_in_2d_and_3d(integrator):
    flat, gravity = random_system(4, 2)
    deep = msd.Body.from_arrays(
        np.c_[flat.positions, np.zeros(len(flat))],
        np.c_[flat.edges().a, flat.edges().b],
        velocities=np.c_[flat.velocities, np.zeros(len(flat))],
        masses=flat.masses,
        fixed=flat.fixed,
        stiffness=flat.edges().stiffness,
        rest_lengths=flat.edges().rest_lengths,
        damping=flat.edges().damping,
    )
    forces_2d = [msd.Gravity(gravity), msd.Ground(-3.0), msd.Drag(0.2)]
    forces_3d = [msd.Gravity([*gravity, 0.0]), msd.Ground(-3.0), msd.Drag(0.2)]
    msd.Simulation(flat, integrator, 1e-3, forces_2d).run(steps=1500)
    msd.Simulation(deep, integrator, 1e-3, forces_3d).run(steps=1500)
    np.testing.assert_allclose(deep.positions[:, :2], flat.positions, atol=1e-9)
    np.testing.assert_allclose(deep.positions[:, 2], 0.0, atol=1e-12)
