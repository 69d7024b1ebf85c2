"""Trampoline scene: the report's outcomes, as numbers, from correct physics."""

import numpy as np
import pytest
from scipy.optimize import minimize

import msdlab as msd
from msdlab.scenes.trampoline import BALL, EXPERIMENTS, experiment_table, run_experiment, trampoline


@pytest.fixture(scope="module")
def outcomes():
    """Every experiment of the report, run for the report's 5 s."""
    return {name: run_experiment(experiment) for name, experiment in EXPERIMENTS.items()}


def test_the_net_is_built_as_the_report_describes():
    sim = trampoline()
    body = sim.body
    assert len(body) == 7 * 7 + 1
    assert body.fixed.sum() == 24  # the perimeter of a 7×7 net
    assert body.n_springs == 2 * 7 * 6
    np.testing.assert_allclose(body.edges().rest_lengths, 0.95)
    np.testing.assert_allclose(body.edges().stiffness, 999.0)
    np.testing.assert_allclose(body.positions[BALL], (3.0, 3.0, 1.5))
    assert body.masses[BALL] == 1.0
    assert body.masses[0] == pytest.approx(0.02)  # nodes have their own mass, not the ball's


def net_equilibrium(size, k, rest, node_mass, load, g=9.8):
    """Static net under a point ``load`` (N) on its centre node: the minimum of its energy.

    Independent of the engine: elastic energy of the links + weight of the nodes + load.
    """
    ij = np.stack(np.meshgrid(np.arange(size), np.arange(size), indexing="ij"), -1).reshape(-1, 2)
    x0 = np.column_stack([ij, np.zeros(len(ij))]).astype(float)
    index = np.arange(size * size).reshape(size, size)
    links = np.vstack(
        [
            np.column_stack([index[:-1].ravel(), index[1:].ravel()]),
            np.column_stack([index[:, :-1].ravel(), index[:, 1:].ravel()]),
        ]
    )
    free = np.flatnonzero(np.all((ij > 0) & (ij < size - 1), axis=1))
    centre = index[size // 2, size // 2]

    def energy(q):
        x = x0.copy()
        x[free] = q.reshape(-1, 3)
        d = x[links[:, 0]] - x[links[:, 1]]
        length = np.linalg.norm(d, axis=1)
        stretch = length - rest
        grad = np.zeros_like(x)
        f = (k * stretch / length)[:, None] * d
        np.add.at(grad, links[:, 0], f)
        np.add.at(grad, links[:, 1], -f)
        grad[:, 2] += node_mass * g
        grad[centre, 2] += load
        e = 0.5 * k * np.sum(stretch**2) + node_mass * g * x[:, 2].sum() + load * x[centre, 2]
        return e, grad[free].ravel()

    start = x0[free] - (0, 0, 0.1)
    result = minimize(energy, start.ravel(), jac=True, method="L-BFGS-B", tol=1e-14)
    x = x0.copy()
    x[free] = result.x.reshape(-1, 3)
    return x[centre]


def test_the_ball_comes_to_rest_where_statics_puts_it():
    """With strong drag the ball settles; its height must be the static equilibrium's."""
    sim = trampoline(drag=5.0)
    trajectory = sim.run(duration=4.0, record_every=100)
    node = net_equilibrium(7, 999.0, 0.95, 0.02, load=1.0 * 9.8)
    expected = node[2] + 0.5 - 1.0 * 9.8 / 1e4  # the ball sinks m g / k_contact into the node
    assert trajectory.positions[-1, BALL, 2] == pytest.approx(expected, abs=2e-3)
    assert node[2] < -0.05  # the net really sags under the ball


def test_heavier_ball_sinks_deeper(outcomes):
    control, heavier = outcomes["control"], outcomes["heavier"]
    assert heavier.deepest < control.deepest - 0.3
    assert heavier.resting < control.resting - 0.15
    assert heavier.fate == control.fate == "rests on a node"


def test_softer_net_sags_more_and_stiffer_less(outcomes):
    soft, control, stiff = outcomes["k-450"], outcomes["control"], outcomes["k-1250"]
    assert soft.deepest < control.deepest - 0.1 < stiff.deepest - 0.1
    assert soft.resting < control.resting < stiff.resting


def test_small_off_centre_ball_falls_through_the_gaps(outcomes):
    """r = 0.5 m: the ball rolls off the node it lands on, away in +x+y, and drops through
    the cell between four nodes, whose half diagonal (0.71 m) is wider than the ball."""
    outcome = outcomes["off-centre"]
    assert outcome.fate == "fell through the net"
    assert outcome.end[2] < -10.0
    drift = outcome.end[:2] - outcome.start[:2]
    assert drift[0] > 0.3 and drift[1] > 0.3


def test_big_off_centre_ball_is_caught_between_four_nodes(outcomes):
    outcome = outcomes["off-centre-big"]
    assert outcome.fate == "caught between four nodes"
    np.testing.assert_allclose(outcome.end[:2], (3.5, 3.5), atol=0.05)
    assert outcome.resting > 0.0  # held on top of the net


def test_on_the_larger_net_an_off_centre_ball_moves_toward_the_centre(outcomes):
    outcome = outcomes["net-11x11"]
    np.testing.assert_allclose(outcome.net_centre, (5.0, 5.0))
    before = np.linalg.norm(outcome.start[:2] - outcome.net_centre)
    after = np.linalg.norm(outcome.end[:2] - outcome.net_centre)
    assert after < before - 0.5
    assert outcome.fate == "caught between four nodes"


def test_the_larger_net_pulls_a_resting_ball_toward_its_centre_only_slightly():
    """Softer near the centre: a big ball resting in a cell nearer the centre sits lower,
    and sits a few mm off its cell's middle toward the centre, but stays in the cell."""
    rest = {}
    for cell in (1.5, 3.5):
        sim = trampoline(size=11, ball_radius=1.0, ball_position=(cell, cell, 1.5), drag=5.0)
        sim.run(duration=4.0, record_every=1000)
        rest[cell] = sim.body.positions[BALL]
    assert rest[3.5][2] < rest[1.5][2] - 0.02
    for cell, position in rest.items():
        shift = position[:2] - cell
        assert np.all((shift > 1e-3) & (shift < 0.02))  # toward (5, 5), within the cell


def test_experiment_table_has_one_row_per_experiment(outcomes):
    table = experiment_table(list(outcomes.values()))
    lines = table.splitlines()
    assert len(lines) == 1 + len(EXPERIMENTS)
    assert all(name in table for name in EXPERIMENTS)


def test_forward_euler_gains_energy_where_velocity_verlet_keeps_it():
    """The report's scheme on an undamped net (nodes of 1 kg): energy grows every step."""
    undamped = {"node_mass": 1.0, "link_damping": 0.0, "drag": 0.0}
    euler = trampoline(integrator=msd.ExplicitEuler(), **undamped).run(duration=2.0)
    verlet = trampoline(**undamped).run(duration=2.0)
    assert euler.energies.total[-1] > 3 * euler.energies.total[0]
    assert verlet.energies.relative_drift() < 1e-3


def test_the_numbers_of_the_scene_docstring():
    """Predicted stable dt ≈ 4 ms for velocity Verlet; forward Euler diverges after about 6 s.

    The blow-up grows out of rounding, so its time depends on the order of the sums:
    6.1 s with the numba kernel, 6.5 s with numpy.
    """
    sim = trampoline()
    assert msd.max_stable_dt(sim.body, msd.VelocityVerlet(), sim.forces) == pytest.approx(
        4e-3, rel=0.05
    )
    euler = trampoline(integrator=msd.ExplicitEuler())
    with pytest.raises(msd.SimulationDiverged) as caught:
        euler.run(duration=10.0, record_every=1000)
    assert 5.5 < caught.value.time < 7.0


def test_bad_net_size_is_refused():
    with pytest.raises(ValueError, match="size >= 3"):
        trampoline(size=2)
