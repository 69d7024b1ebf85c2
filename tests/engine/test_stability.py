"""Predicted stable dt against analytic limits and measured blow-ups; divergence detection."""

import math

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.simulation import stability


def chain(n: int = 8, dim: int = 2) -> msd.Body:
    x = np.zeros((n, dim))
    x[:, 0] = np.arange(n)
    return msd.Body.from_arrays(
        x, [[i, i + 1] for i in range(n - 1)], stiffness=4.0, masses=np.linspace(1, 2, n)
    )


def kicked(body: msd.Body, size: float = 0.01) -> msd.Body:
    """The body with every particle moved randomly by about ``size`` (m)."""
    body.positions = body.positions + size * np.random.default_rng(0).standard_normal(
        body.positions.shape
    )
    return body


def grid() -> msd.Body:
    return msd.Body.grid((4, 4, 4), spacing=0.2, stiffness=30.0, neighbours=(1, 2, 3))


@pytest.mark.parametrize(
    "integrator, limit",
    [
        (msd.SymplecticEuler(), 2.0),
        (msd.Verlet(), 2.0),
        (msd.Verlet(0.3), math.sqrt(4 - 2 * 0.3)),
        (msd.VelocityVerlet(), 2.0),
        (msd.RK4(), 2 * math.sqrt(2)),
        (msd.ExplicitEuler(), 0.0),
        (msd.ImplicitEuler(), math.inf),
    ],
    ids=repr,
)
def test_stability_limit_of_one_mode_matches_theory(integrator, limit):
    omega = 3.0
    assert msd.stability_limit(integrator, msd.Mode(omega)) * omega == pytest.approx(
        limit, rel=1e-6
    )


def test_explicit_euler_is_stable_with_enough_damping():
    """|1 + dt μ| <= 1 for μ = -γ/2 ± i√(ω² - γ²/4) gives dt <= γ/ω²."""
    mode = msd.Mode(omega=10.0, gamma=2.0)
    assert msd.stability_limit(msd.ExplicitEuler(), mode) == pytest.approx(2.0 / 100, rel=1e-6)


class Frozen(msd.Integrator):
    """A student's integrator that moves nothing: stable at every dt."""

    def step(self, x, v, dt, dynamics):
        return x.copy(), v.copy()


class ForwardEuler(msd.Integrator):
    """Explicit Euler as a student writes it: unstable at any dt without damping."""

    def step(self, x, v, dt, dynamics):
        return x + dt * v, v + dt * dynamics.acceleration(x, v)


class Growing(msd.Integrator):
    """A student's integrator that adds a thousandth every step: unstable at every dt."""

    def step(self, x, v, dt, dynamics):
        return 1.001 * x, 1.001 * v


def fine_scan_limit(integrator: msd.Integrator, mode: msd.Mode) -> float:
    """The stable limit from a fine scan: 40 trial dts a decade from 10⁻⁶/ω to the first
    unstable one, bisected to a relative 10⁻¹⁰ (0 below 10⁻⁵/ω, inf above 1000/ω)."""
    stable = 0.0
    for dt in np.logspace(-6, 3, 361) / mode.omega:
        if stability.spectral_radius(integrator, mode, dt) > 1.0 + 1e-12:
            break
        stable = dt
    else:
        return math.inf
    if stable < 1e-5 / mode.omega:
        return 0.0
    low, high = stable, dt
    while high - low > 1e-10 * low:
        middle = 0.5 * (low + high)
        unstable = stability.spectral_radius(integrator, mode, middle) > 1.0 + 1e-12
        low, high = (low, middle) if unstable else (middle, high)
    return low


@pytest.mark.parametrize(
    "integrator",
    [
        msd.SymplecticEuler(),
        msd.Verlet(),
        msd.Verlet(0.6),
        msd.VelocityVerlet(),
        msd.RK4(),
        msd.ExplicitEuler(),
        msd.ImplicitEuler(),
        Frozen(),
        ForwardEuler(),
        Growing(),
    ],
    ids=lambda integrator: type(integrator).__name__,
)
@pytest.mark.parametrize("mode", [msd.Mode(3.0), msd.Mode(40.0, 2.0)], ids=repr)
def test_the_search_finds_the_limit_of_a_fine_scan(integrator, mode):
    """The scan of 4 trial dts a decade and its bisection find the limit a scan of 40 a decade
    finds, to the relative 10⁻⁸ the search promises."""
    fine = fine_scan_limit(integrator, mode)
    found = msd.stability_limit(integrator, mode)
    assert found == pytest.approx(fine, rel=1e-8) if 0 < fine < math.inf else found == fine


def test_stiffest_mode_of_two_bodies_is_the_analytic_frequency():
    body = msd.Body.from_arrays(
        [[0.0, 0.0], [1.0, 0.0]], [[0, 1]], masses=[1.0, 2.0], stiffness=10.0
    )
    assert msd.stiffest_mode(body).omega == pytest.approx(math.sqrt(10.0 * 1.5), rel=1e-12)


@pytest.mark.parametrize("make_body", [chain, grid], ids=["chain", "grid"])
@pytest.mark.parametrize(
    "integrator", [msd.SymplecticEuler(), msd.Verlet(), msd.Verlet(0.2)], ids=repr
)
def test_predicted_limit_matches_measured_blowup(make_body, integrator):
    body = make_body()
    predicted = msd.max_stable_dt(body, integrator)
    measured = msd.measure_blowup_dt(body, integrator, steps=600, rtol=0.01)
    assert measured == pytest.approx(predicted, rel=0.10)


def test_implicit_euler_stays_bounded_at_ten_times_the_explicit_limit():
    body = grid()
    dt = 10 * msd.max_stable_dt(body, msd.SymplecticEuler())
    kicked(body)
    trajectory = msd.Simulation(body, msd.ImplicitEuler(), dt).run(steps=200, record_every=10)
    total = trajectory.energies.total
    assert np.all(np.isfinite(total)) and np.all(np.diff(total) <= 1e-12)


def test_blowup_is_caught_in_the_step_it_happens_and_explained():
    body = chain()
    limit = msd.max_stable_dt(body, msd.SymplecticEuler())
    kicked(body)
    sim = msd.Simulation(body, msd.SymplecticEuler(), 1.5 * limit)
    with pytest.raises(msd.SimulationDiverged) as caught:
        sim.run(steps=10_000, record_every=100)
    error = caught.value
    assert np.all(np.isfinite(body.positions))  # the body keeps its last finite state
    assert error.step == sim.step_count  # raised in the failing step, state not committed
    assert error.step < 200  # caught while growing, long before overflow
    message = str(error)
    assert "spring" in message and "particle" in message
    assert f"{limit:.3g} s" in message and "1.5× the predicted stable limit" in message
    assert len(error.trajectory) >= 1


def test_non_finite_state_is_caught_at_once():
    class Poison(msd.Integrator):
        def step(self, x, v, dt, dynamics):
            x_new = x + dt * v
            x_new[2, 0] = np.nan
            return x_new, v

    sim = msd.Simulation(chain(), Poison(), 0.01)  # also: Poison cannot step a 1-particle mode
    with pytest.raises(msd.SimulationDiverged, match=r"step 0 .*particle 2 got a non-finite"):
        sim.step()


def test_explicit_euler_blowup_says_it_is_unstable_at_any_dt():
    with pytest.raises(msd.SimulationDiverged, match="unstable at any dt") as raised:
        msd.Simulation(kicked(chain()), msd.ExplicitEuler(), 0.3).run(steps=100_000)
    assert "ExplicitEuler is unstable" in str(raised.value)
    assert "use SymplecticEuler, Verlet" in str(raised.value)


def test_a_users_integrator_that_blows_up_is_to_be_fixed_not_replaced():
    """The integrator a user wrote (a course's task: the integrator is the exercise) is told
    to be compared with its equation, never to be swapped for one of the engine's; the
    message has no unit of length of its own (the course's are the template's)."""
    with pytest.raises(msd.SimulationDiverged, match="unstable at any dt") as raised:
        msd.Simulation(kicked(chain()), ForwardEuler(), 0.3).run(steps=100_000)
    message = str(raised.value)
    assert "your integrator is unstable" in message and "scheme's equation" in message
    assert "ForwardEuler" not in message and "use SymplecticEuler" not in message
    assert "ImplicitEuler" not in message and "m/s" not in message


@pytest.mark.parametrize(
    "integrator",
    [
        msd.ExplicitEuler(),
        msd.SymplecticEuler(),
        msd.Verlet(0.1),
        msd.VelocityVerlet(),
        msd.RK4(),
        msd.ImplicitEuler(),
    ],
    ids=repr,
)
def test_fixed_particles_never_move(integrator):
    body = msd.Body.grid((3, 3, 3), spacing=0.5, stiffness=50.0, neighbours=(1, 2), damping=0.5)
    body.fixed[[0, 13]] = True
    body.positions[0, 1] = -1.0  # pinned below the floor: the floor must not move it
    start = body.positions[[0, 13]].copy()
    forces = [msd.Gravity((0, -9.81, 0)), msd.Ground(-0.5), msd.Drag(0.1), msd.ViscousDamping(0.1)]
    msd.Simulation(body, integrator, 2e-3, forces).run(steps=300)
    np.testing.assert_array_equal(body.positions[[0, 13]], start)
    np.testing.assert_array_equal(body.velocities[[0, 13]], 0.0)
