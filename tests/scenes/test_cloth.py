"""Hanging cloth scene: it sags, stays bounded, loses energy through λ, and explicit Euler's
blow-up at the notebook's settings is caught and explained."""

import numpy as np
import pytest

import msdlab as msd
from msdlab.scenes.cloth import cloth


def test_mesh_matches_the_notebook():
    sim = cloth()
    x = sim.body.positions
    assert len(x) == 100
    np.testing.assert_allclose(x.min(axis=0), (0.0, 0.0, 10.0))
    np.testing.assert_allclose(x.max(axis=0), (10.0, 8.0, 10.0))
    pinned = x[sim.body.fixed]
    np.testing.assert_allclose(pinned, [[0.0, 8.0, 10.0], [10.0, 8.0, 10.0]])
    assert cloth(pin="row").body.fixed.sum() == 10
    assert cloth(shear=False).body.n_springs == 2 * 10 * 9


def test_it_sags_and_the_pins_hold():
    sim = cloth()
    start = sim.body.positions.copy()
    trajectory = sim.run(duration=3.0, record_every=50)
    end = trajectory.positions[-1]
    free = ~sim.body.fixed
    assert end[free, 2].mean() < start[free, 2].mean() - 3.0
    np.testing.assert_array_equal(end[~free], start[~free])


@pytest.mark.parametrize(
    "integrator",
    [msd.SymplecticEuler(), msd.VelocityVerlet(), msd.Verlet(), msd.ImplicitEuler()],
    ids=lambda i: type(i).__name__,
)
def test_it_stays_bounded_with_a_stable_integrator(integrator):
    sim = cloth(integrator=integrator)
    trajectory = sim.run(duration=5.0, record_every=25)
    x = trajectory.positions
    assert np.all(np.isfinite(x))
    # Hanging from (0, 8, 10) and (10, 8, 10), nothing can drop further than the cloth is long.
    assert x[..., 2].min() > 10.0 - 1.3 * np.hypot(10.0, 8.0)
    d = x[-1, sim.body.edges().a] - x[-1, sim.body.edges().b]
    assert np.max(np.linalg.norm(d, axis=1) / sim.body.edges().rest_lengths) < 1.5


def test_energy_decays_with_damping_and_is_kept_without():
    damped = cloth().run(duration=10.0, record_every=50).energies
    total = damped.total
    assert total[-1] < total[0] - 300.0  # λ took out a third of the energy
    assert damped.kinetic[-1] < 1e-3 * max(damped.kinetic)  # and brought the cloth to rest
    per_second = total[::2]  # frames every 0.5 s -> one per second
    assert np.all(np.diff(per_second) < 1e-6)
    undamped = cloth(damping=0.0).run(duration=3.0, record_every=50).energies
    assert abs(undamped.total[-1] - undamped.total[0]) < 0.05 * undamped.total[0]


def test_explicit_euler_blows_up_at_the_notebook_settings_and_says_why():
    sim = cloth(integrator=msd.ExplicitEuler())
    limit = msd.max_stable_dt(sim.body, msd.ExplicitEuler(), sim.forces)
    assert limit < sim.dt / 10  # the linear analysis predicts the blow-up
    with pytest.raises(msd.SimulationDiverged) as caught:
        sim.run(duration=10.0)
    error = caught.value
    assert error.time < 2.0
    assert "ExplicitEuler" in error.diagnosis and "stable limit" in error.diagnosis
    assert np.all(np.isfinite(sim.body.positions))  # the last finite state is kept, no NaN
    assert error.trajectory is not None and len(error.trajectory) > 1


def test_the_numbers_of_the_cloth_notebook():
    """Forward Euler at dt = 0.01 s is 85 times over its limit and blows up within 1 s."""
    sim = cloth(integrator=msd.ExplicitEuler())
    limit = msd.max_stable_dt(sim.body, msd.ExplicitEuler(), sim.forces)
    assert round(sim.dt / limit) == 85
    with pytest.raises(msd.SimulationDiverged) as caught:
        sim.run(duration=10.0, record_every=10)
    assert caught.value.time < 1.0 and caught.value.step < 100


def test_explicit_euler_below_the_predicted_limit_is_stable():
    sim = cloth(integrator=msd.ExplicitEuler())
    sim.dt = 0.8 * msd.max_stable_dt(sim.body, msd.ExplicitEuler(), sim.forces)
    trajectory = sim.run(steps=3000, record_every=500)
    assert np.all(np.isfinite(trajectory.positions))
    assert trajectory.energies.total[-1] < trajectory.energies.total[0]


def test_unknown_pin_names_the_choices():
    with pytest.raises(ValueError, match="corners, row"):
        cloth(pin="left")
