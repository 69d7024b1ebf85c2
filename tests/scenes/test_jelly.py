"""Jelly cube scene: the brief's template, free fall, landing, and tasks 3-4 (shape)."""

import numpy as np
import pytest

from msdlab.scenes.jelly import jelly_cube


def height(x):
    return x[:, 1].max() - x[:, 1].min()


def test_grid_is_the_briefs():
    sim = jelly_cube(size=20, angle=0.0)
    x = sim.body.positions
    assert len(x) == 8000
    np.testing.assert_allclose(x.min(axis=0), (-1.0, 1.5, -1.0))
    np.testing.assert_allclose(x.max(axis=0), (0.9, 3.4, 0.9))
    np.testing.assert_allclose(sim.body.edges().rest_lengths.min(), 0.1)  # one grid spacing, 2/N
    assert (sim.dt, sim.integrator.damping) == (0.4, 0.01)


def test_undamped_free_fall_follows_the_template_exactly():
    """Template: after n steps from rest, y = y0 + a dt² n(n+1)/2 (before any contact)."""
    sim = jelly_cube(size=5, damping=0.0)
    y0 = sim.body.positions[:, 1].copy()
    n = 60
    sim.run(steps=n)
    np.testing.assert_allclose(sim.body.positions[:, 1], y0 - 0.001 * 0.4**2 * n * (n + 1) / 2)


@pytest.fixture(scope="module")
def landed():
    sim = jelly_cube(size=6)
    start = sim.body.positions.copy()
    return sim, start, sim.run(steps=1500, record_every=50)


def test_it_lands_on_the_floor_and_comes_to_rest(landed):
    _, start, trajectory = landed
    assert start[:, 1].min() > 1.0
    assert trajectory.positions[..., 1].min() >= 0.0
    assert trajectory.positions[-1, :, 1].min() == pytest.approx(0.0, abs=1e-3)
    assert trajectory.energies.kinetic[-1] < 1e-3 * max(trajectory.energies.kinetic)


def test_with_26_neighbours_it_keeps_its_shape(landed):
    """Task 4: the rotated cube lands on an edge, tips onto a face and stays a cube."""
    sim, _, trajectory = landed
    side = 5 * 2.0 / 6
    assert height(trajectory.positions[-1]) == pytest.approx(side, rel=0.05)
    x = trajectory.positions[-1]
    lengths = np.linalg.norm(x[sim.body.edges().a] - x[sim.body.edges().b], axis=1)
    assert np.max(np.abs(lengths / sim.body.edges().rest_lengths - 1)) < 0.05


def test_with_axis_springs_only_the_rotated_cube_collapses():
    """Task 3: six axis springs give no shear stiffness, so the tilted cube folds flat."""
    sim = jelly_cube(size=6, neighbours=(1,))
    sim.run(steps=600)
    assert height(sim.body.positions) < 0.1 * 5 * 2.0 / 6
