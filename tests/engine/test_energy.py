"""Energy behaviour of the integrators, conservation laws and the energy ledger."""

import itertools

import numpy as np
import pytest

import msdlab as msd


def chain(damping: float = 0.0) -> msd.Body:
    """A free 2-D chain of 6 particles, stretched and kicked."""
    rng = np.random.default_rng(3)
    x = np.c_[np.arange(6.0) * 1.1, rng.normal(0, 0.05, 6)]
    body = msd.Body.from_arrays(
        x,
        [[i, i + 1] for i in range(5)],
        masses=rng.uniform(1, 2, 6),
        stiffness=20.0,
        rest_lengths=1.0,
        damping=damping,
        velocities=rng.normal(0, 0.2, (6, 2)),
    )
    body.velocities = body.velocities - msd.momentum(body) / body.masses.sum()
    return body


def relative_energy_error(integrator: msd.Integrator, dt: float, duration: float) -> np.ndarray:
    trajectory = msd.Simulation(chain(), integrator, dt).run(duration=duration)
    total = trajectory.energies.total
    return np.abs(total - total[0]) / total[0]


def eighths(error: np.ndarray) -> list[float]:
    return [part.max() for part in np.array_split(error, 8)]


def test_velocity_verlet_energy_error_is_second_order_and_bounded():
    coarse = relative_energy_error(msd.VelocityVerlet(), 0.02, 40.0)
    fine = relative_energy_error(msd.VelocityVerlet(), 0.01, 40.0)
    assert coarse.max() / fine.max() == pytest.approx(4.0, rel=0.25)  # O(dt²)
    parts = eighths(relative_energy_error(msd.VelocityVerlet(), 0.02, 400.0))
    assert max(parts) < 1.5 * parts[0] < 5e-3  # bounded: no growth over 20 000 steps


def test_brief_verlet_without_damping_does_not_drift():
    parts = eighths(relative_energy_error(msd.Verlet(), 0.02, 400.0))
    assert max(parts) < 1.5 * parts[0] < 1e-2


def test_rk4_energy_drifts_steadily_unlike_the_symplectic_schemes():
    parts = eighths(relative_energy_error(msd.RK4(), 0.02, 400.0))
    assert all(later > earlier for earlier, later in itertools.pairwise(parts))
    assert parts[-1] > 3 * parts[0]


def test_explicit_euler_energy_grows():
    error = relative_energy_error(msd.ExplicitEuler(), 0.005, 20.0)
    trajectory_total = error[-1]
    assert trajectory_total > 0.3 and np.all(np.diff(error[::200]) > 0)


@pytest.mark.parametrize(
    "integrator, forces, damping",
    [
        (msd.Verlet(0.02), [], 0.0),
        (msd.VelocityVerlet(), [], 0.5),
        (msd.SymplecticEuler(), [msd.Drag(0.5)], 0.0),
        (msd.RK4(), [msd.ViscousDamping(0.3)], 0.0),
        (msd.ImplicitEuler(), [], 0.0),
    ],
    ids=["verlet-lambda", "dashpots", "drag", "viscous", "implicit"],
)
def test_damped_runs_lose_energy_monotonically(integrator, forces, damping):
    trajectory = msd.Simulation(chain(damping), integrator, 0.01, forces).run(duration=20.0)
    total = trajectory.energies.total
    assert total[-1] < 0.5 * total[0]
    assert np.all(np.diff(total[::50]) < 1e-12)


@pytest.mark.parametrize(
    "integrator, forces, damping, source",
    [
        (msd.Verlet(0.02), [], 0.0, "integrator"),
        (msd.VelocityVerlet(), [], 0.5, "dashpot"),
        (msd.VelocityVerlet(), [msd.Drag(0.5)], 0.0, "drag"),
        (msd.VelocityVerlet(), [msd.ViscousDamping(0.4)], 0.0, "viscous"),
    ],
    ids=["verlet-lambda", "dashpots", "drag", "viscous"],
)
def test_ledger_books_the_loss_to_its_source_and_closes(integrator, forces, damping, source):
    trajectory = msd.Simulation(chain(damping), integrator, 0.005, forces).run(duration=10.0)
    ledger = trajectory.energies
    lost = ledger.total[0] - ledger.total[-1]
    assert ledger.dissipated[source][-1] == pytest.approx(lost, rel=0.03)
    assert abs(ledger.drift[-1]) < 0.03 * lost


def test_ledger_books_ground_impact():
    body = msd.Body.grid((3, 3), spacing=0.2, stiffness=200.0, neighbours=(1, 2), origin=(0, 0.5))
    sim = msd.Simulation(
        body, msd.VelocityVerlet(), 1e-3, [msd.Gravity((0, -9.81)), msd.Ground(0.0, friction=0.5)]
    )
    ledger = sim.run(duration=1.0).energies
    assert ledger.dissipated["ground"][-1] > 0.2 * (ledger.total[0] - ledger.total[-1])
    assert abs(ledger.drift[-1]) < 0.1 * (ledger.total[0] - ledger.total[-1])


def test_momentum_and_angular_momentum_are_conserved():
    body = chain(damping=0.3)
    body.velocities = body.velocities + [0.5, -0.2]
    p0, l0 = msd.momentum(body).copy(), msd.angular_momentum(body)
    msd.Simulation(body, msd.VelocityVerlet(), 0.005).run(duration=5.0)
    np.testing.assert_allclose(msd.momentum(body), p0, atol=1e-12)
    assert msd.angular_momentum(body) == pytest.approx(l0, abs=1e-10)


def test_energy_functions_on_a_known_state():
    body = msd.Body.from_arrays(
        [[0.0, 1.0, 0.0], [2.0, 3.0, 0.0]],
        [[0, 1]],
        masses=[1.0, 2.0],
        velocities=[[1.0, 0, 0], [0, 2.0, 0]],
        rest_lengths=[2.0],
        stiffness=4.0,
    )
    assert msd.kinetic_energy(body) == pytest.approx(0.5 * 1 + 0.5 * 2 * 4)
    assert msd.elastic_energy(body) == pytest.approx(0.5 * 4 * (8**0.5 - 2) ** 2)
    assert msd.gravitational_energy(body, (0, -9.81, 0)) == pytest.approx(9.81 * (1 + 2 * 3))
    np.testing.assert_allclose(msd.momentum(body), [1.0, 4.0, 0.0])
    np.testing.assert_allclose(msd.angular_momentum(body), [0, 0, -1.0 + 2 * 2 * 2])


def test_without_the_ledger_the_run_is_the_same_and_losses_show_as_drift():
    def run(ledger: bool) -> tuple[msd.Body, msd.EnergyLedger]:
        body = msd.Body.grid((3, 3), spacing=0.2, stiffness=200.0, neighbours=(1, 2), damping=0.2)
        body.positions = body.positions + [0.0, 0.3]
        forces = [msd.Gravity((0, -9.81)), msd.Ground(0.0), msd.Drag(0.3)]
        sim = msd.Simulation(body, msd.Verlet(0.01), 1e-3, forces, ledger=ledger)
        return body, sim.run(duration=1.0, record_every=100).energies

    booked_body, booked = run(True)
    plain_body, plain = run(False)
    np.testing.assert_array_equal(plain_body.positions, booked_body.positions)
    np.testing.assert_allclose(plain.total, booked.total)
    assert plain.dissipated == {} and set(booked.dissipated) >= {"ground", "drag", "dashpot"}
    np.testing.assert_allclose(plain.drift, booked.drift - booked.total_dissipated)
