"""Pictures stand upright by default: "up" is against the scene's gravity or off its floor."""

import pytest

import msdlab as msd
from msdlab import viz
from msdlab.viz.upright import up_of, up_of_run


def cube(gravity: tuple[float, float, float], floor_normal=None) -> msd.Simulation:
    body = msd.Body.grid((3, 3, 3), spacing=0.1, stiffness=500.0)
    body.positions += 0.5
    forces = [msd.Ground(0.0, normal=floor_normal)] if floor_normal else []
    if any(gravity):
        forces.insert(0, msd.Gravity(gravity))
    return msd.Simulation(body, msd.Verlet(0.01), dt=1e-3, forces=forces)


@pytest.mark.parametrize(
    ("gravity", "up"), [((0.0, -9.81, 0.0), "y"), ((0.0, 0.0, -9.81), "z"), ((-9.81, 0, 0), "x")]
)
def test_up_is_against_gravity_for_a_simulation_and_for_its_run(gravity, up):
    sim = cube(gravity)
    assert up_of(sim) == up
    assert up_of_run(sim.run(steps=100, record_every=10)) == up


def test_without_gravity_the_floor_decides_and_else_z():
    assert up_of(cube((0.0, 0.0, 0.0), floor_normal=(0.0, 1.0, 0.0))) == "y"
    assert up_of(cube((0.0, 0.0, 0.0))) == "z"


def test_the_readme_cube_is_drawn_with_y_up_unless_told_otherwise():
    import matplotlib.pyplot as plt

    sim = cube((0.0, -9.81, 0.0))
    run = sim.run(steps=50, record_every=10)
    animation = viz.animate(run, max_frames=3)
    assert animation._fig.axes[0]._vertical_axis == 1  # y is the screen's vertical
    assert animation.to_jshtml().count("data:image/png;base64") == 3  # drawn, not just built
    figure = viz.plot_body(sim)
    assert figure.axes[0]._vertical_axis == 1
    assert viz.plot_body(sim, up="z").axes[0]._vertical_axis == 2
    plt.close("all")
