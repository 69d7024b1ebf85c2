"""Integrators against analytic solutions: period, convergence order, the brief's Verlet."""

import math

import numpy as np
import pytest
from scipy.signal import find_peaks

import msdlab as msd

K, M1, M2, STRETCH = 10.0, 1.0, 2.0, 0.1
OMEGA = math.sqrt(K * (1 / M1 + 1 / M2))  # two-body oscillator


def two_body(stretch: float = STRETCH, velocity: float = 0.0) -> msd.Body:
    """Two masses on a spring of rest length 1, released stretched by ``stretch``."""
    return msd.Body.from_arrays(
        [[0.0, 0.0, 0.0], [1.0 + stretch, 0.0, 0.0]],
        [[0, 1]],
        velocities=[[0.0, 0.0, 0.0], [velocity, 0.0, 0.0]],
        masses=[M1, M2],
        stiffness=K,
        rest_lengths=[1.0],
    )


def separation(integrator: msd.Integrator, dt: float, duration: float, **kw) -> float:
    body = two_body(**kw)
    msd.Simulation(body, integrator, dt).run(duration=duration)
    return body.positions[1, 0] - body.positions[0, 0]


def test_period_matches_two_body_frequency():
    body = two_body()
    trajectory = msd.Simulation(body, msd.RK4(), 1e-3).run(duration=10.0)
    length = trajectory.positions[:, 1, 0] - trajectory.positions[:, 0, 0]
    peaks, _ = find_peaks(length)
    period = np.mean(np.diff(trajectory.times[peaks]))
    assert period == pytest.approx(2 * math.pi / OMEGA, rel=1e-4)


DTS = [4e-3, 2e-3, 1e-3, 5e-4]
EXACT = 1.0 + STRETCH * math.cos(OMEGA * 1.0)


@pytest.mark.parametrize(
    "integrator, order",
    [
        (msd.ExplicitEuler(), 1),
        (msd.SymplecticEuler(), 1),
        (msd.ImplicitEuler(), 1),
        (msd.VelocityVerlet(), 2),
        (msd.RK4(), 4),
    ],
    ids=lambda p: repr(p) if isinstance(p, msd.Integrator) else str(p),
)
def test_observed_convergence_order(integrator, order):
    result = msd.convergence_order(lambda dt: separation(integrator, dt, 1.0), DTS, EXACT)
    assert result.order == pytest.approx(order, abs=0.15), str(result)


def test_brief_verlet_with_template_start_is_first_order():
    """x_old = x - v·dt misses ½ a dt²: first order when the body starts accelerating."""
    result = msd.convergence_order(lambda dt: separation(msd.Verlet(), dt, 1.0), DTS, EXACT)
    assert result.order == pytest.approx(1.0, abs=0.15), str(result)


def test_brief_verlet_is_second_order_with_a_taylor_start():
    """Storing v0 - ½ a0 dt makes x_old = x0 - v0 dt + ½ a0 dt² (a Taylor start): order 2."""

    def solve(dt: float) -> float:
        body = two_body()
        sim = msd.Simulation(body, msd.Verlet(), dt)
        a0 = sim.dynamics.acceleration(body.positions, body.velocities)
        body.velocities = body.velocities - 0.5 * dt * a0
        sim.run(duration=1.0)
        return body.positions[1, 0] - body.positions[0, 0]

    result = msd.convergence_order(solve, DTS, EXACT)
    assert result.order == pytest.approx(2.0, abs=0.15), str(result)


def test_brief_verlet_is_second_order_when_the_start_is_not_accelerating():
    """Released at rest length with a velocity, a(0) = 0 and the template start is exact enough."""
    speed = 0.3
    exact = 1.0 + speed / OMEGA * math.sin(OMEGA * 1.0)
    result = msd.convergence_order(
        lambda dt: separation(msd.Verlet(), dt, 1.0, stretch=0.0, velocity=speed), DTS, exact
    )
    assert result.order == pytest.approx(2.0, abs=0.15), str(result)


def test_verlet_damping_is_equation_1_4():
    """One step by hand: x_new = (2 - λ) x - (1 - λ) x_old + a dt²."""
    lam, dt = 0.25, 0.1
    body = msd.Body.from_arrays(
        [[0.0, 0.0], [1.5, 0.0]],
        [[0, 1]],
        velocities=[[0, 0], [0.4, 0]],
        stiffness=2.0,
        rest_lengths=[1.0],
        fixed=[True, False],
    )
    x, v = body.positions[1].copy(), body.velocities[1].copy()
    msd.Simulation(body, msd.Verlet(lam), dt).step()
    a = np.array([-2.0 * 0.5, 0.0])
    expected = (2 - lam) * x - (1 - lam) * (x - v * dt) + a * dt**2
    np.testing.assert_allclose(body.positions[1], expected, rtol=1e-15)
    np.testing.assert_allclose(body.velocities[1], (expected - x) / dt, rtol=1e-14)
