"""Static plots: a body with springs coloured by strain (2-D and 3-D), the energy ledger."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.patches import Circle
from matplotlib.path import Path

import msdlab as msd
from msdlab import viz
from msdlab.scenes import cloth, gallery, trampoline
from msdlab.viz.lines import LEVELS, SpringLines


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_strain_is_relative_stretch():
    body = msd.Body.from_arrays([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]], [[0, 1], [0, 2]])
    body.set_springs(rest_lengths=[1.0, 2.0])
    np.testing.assert_allclose(viz.strains(body.edges(), body.positions), [1.0, -0.5])


def test_2d_body_springs_carry_their_strains(tmp_path):
    sim = gallery.two_particles(pull=50.0)
    path = tmp_path / "body.png"
    figure = viz.plot_body(sim.body, title="pulled", save=path)
    ax = figure.axes[0]
    (springs,) = [c for c in ax.collections if isinstance(c, LineCollection)]
    np.testing.assert_allclose(springs.values, [0.5])  # 150 px over a rest of 100
    np.testing.assert_allclose(springs.ends[0], [[250.0, 200.0], [400.0, 200.0]])
    assert ax.get_title() == "pulled"
    assert path.stat().st_size > 1000
    assert figure.get_size_inches()[0] * 100 >= 600  # report-sized: at least 600 px wide


def test_3d_body_uses_the_reports_view_angles():
    sim = trampoline.trampoline()
    ax = viz.plot_body(sim.body, view=(45.0, 45.0), spheres=viz.spheres_of(sim)).axes[0]
    assert (ax.azim, ax.elev) == (45.0 - 90.0, 45.0)  # azimuth measured from -y, as in MATLAB
    ax = viz.plot_body(sim.body, view=(0.0, 0.0)).axes[0]
    assert (ax.azim, ax.elev) == (-90.0, 0.0)  # looking along +y
    assert viz.spheres_of(sim) == [(49, 0.5)]


def test_a_ball_is_drawn_where_the_particle_is():
    body = msd.Body.from_arrays([[0.0, 0.0], [1.0, 0.0]], [[0, 1]])
    ax = viz.plot_body(body, spheres=[(1, 0.25)]).axes[0]
    (ball,) = [p for p in ax.patches if isinstance(p, Circle)]
    np.testing.assert_array_equal(ball.center, (1.0, 0.0))
    assert ball.radius == 0.25


def test_body_view_follows_new_positions():
    sim = cloth.cloth()
    ax = viz.new_axes(sim.body)
    drawing = viz.BodyView(ax, sim.body)
    sim.run(steps=50)
    drawing.update(sim.body.positions)
    *_, z = drawing.free.get_data_3d()
    np.testing.assert_allclose(z, sim.body.positions[~sim.body.fixed, 2])
    np.testing.assert_allclose(
        drawing.springs.values, viz.strains(sim.body.edges(), sim.body.positions)
    )


def test_wrong_axes_or_vertical_axis_are_refused():
    sim = cloth.cloth()
    _, flat = plt.subplots()
    with pytest.raises(ValueError, match="3-D body needs 3-D axes"):
        viz.BodyView(flat, sim.body)
    with pytest.raises(ValueError, match="x, y, z"):
        viz.plot_body(sim.body, up="w")


def test_a_net_can_be_coloured_by_its_sag_below_the_rim():
    body = trampoline.trampoline().body  # a flat net at the rim's height, z = 0
    positions = body.positions.copy()
    middle = 24  # the net's centre particle
    positions[middle, 2] -= 0.5
    figure = viz.plot_body(body, positions, colour="sag", strain_limit=1.0)
    (springs,) = figure.axes[0].collections[:1]
    touching = (body.edges().a == middle) | (body.edges().b == middle)
    np.testing.assert_allclose(springs.values[touching], 0.25)  # their middles sag 0.25
    np.testing.assert_allclose(springs.values[~touching], 0.0)
    assert figure.axes[1].get_xlabel() == "sag below the rim"  # the colour bar, below the box


def test_spring_lines_draw_every_spring_once_in_the_colour_of_its_value():
    """Springs are grouped by colour level into one path each; every spring's segment is in
    the path whose colour value is within half a level of its own (clipped to the scale)."""
    rng = np.random.default_rng(3)
    ends = rng.normal(size=(500, 2, 2))
    values = rng.normal(scale=0.6, size=500)  # some beyond the scale's ±1
    springs = SpringLines(ends, values, cmap="coolwarm", norm=Normalize(-1.0, 1.0))
    half_level = 0.5 * 2.0 / LEVELS
    drawn = []
    for path, value in zip(springs.get_paths(), springs.get_array()):
        segments = path.vertices.reshape(-1, 2, 2)
        assert list(path.codes) == [Path.MOVETO, Path.LINETO] * len(segments)
        for segment in segments:
            (spring,) = np.flatnonzero((ends == segment).all(axis=(1, 2)))
            assert abs(np.clip(values[spring], -1, 1) - value) <= half_level + 1e-12
            drawn.append(spring)
    assert sorted(drawn) == list(range(500))


def test_sag_colouring_needs_a_3d_body():
    with pytest.raises(ValueError, match="'sag' \\(3-D\\)"):
        viz.plot_body(gallery.rope().body, colour="sag")
    with pytest.raises(ValueError, match="cannot colour springs by 'height'"):
        viz.plot_body(cloth.cloth().body, colour="height")


def test_energy_plot_shows_the_ledger(tmp_path):
    trajectory = gallery.triangle().run(steps=200, record_every=10)
    ax = viz.plot_energy(trajectory.energies, time_unit="frames").axes[0]
    labels = [line.get_label() for line in ax.get_lines()]
    assert labels[:4] == ["kinetic", "elastic", "potential", "total"]
    assert "taken out: drag" in labels and labels[-1].startswith("drift")
    np.testing.assert_allclose(ax.get_lines()[3].get_ydata(), trajectory.energies.total)
    assert ax.get_xlabel() == "time (frames)"
    ax.figure.savefig(tmp_path / "energy.png")
    assert (tmp_path / "energy.png").stat().st_size > 1000
