"""Dragging particles with the mouse: synthetic mouse events through the canvas callbacks."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.backend_bases import MouseEvent

import msdlab as msd
from msdlab import viz
from msdlab.scenes import cloth, gallery


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def mouse(dragger, name, point, button=1):
    """Send a mouse event at the pixel nearest to ``point`` (2-D data coordinates) through
    the figure's callbacks; return the data coordinates of that pixel."""
    x, y = np.round(dragger.ax.transData.transform(point))
    canvas = dragger.ax.figure.canvas
    canvas.callbacks.process(name, MouseEvent(name, canvas, x, y, button=button))
    return dragger.ax.transData.inverted().transform((x, y))


def test_press_grabs_the_nearest_particle_and_it_follows_the_mouse():
    dragger = viz.Dragger(gallery.mesh(gravity=0.0))
    body = dragger.sim.body
    near = body.positions[37] + (4.0, -3.0)
    mouse(dragger, "button_press_event", near)
    assert dragger.grab.particle == 37
    target = mouse(dragger, "motion_notify_event", body.positions[37] + (60.0, 25.0))
    for _ in range(5):
        dragger.advance()
    np.testing.assert_allclose(body.positions[37], target, atol=1e-6)
    neighbour = body.positions[38]
    assert not np.allclose(neighbour, dragger.sim.initial_positions[38])  # the mesh followed


def test_release_does_not_fling_the_particle():
    """Held still against stretched springs, the particle is let go at rest: the page
    pegged the position only and let the velocity build up, so it flew off on release."""
    dragger = viz.Dragger(gallery.hanging_particle(damping=1.0))
    body = dragger.sim.body
    mouse(dragger, "button_press_event", body.positions[1])
    mouse(dragger, "motion_notify_event", body.positions[1] - (0.0, 80.0))  # stretch the spring
    for _ in range(30):
        dragger.advance()
    mouse(dragger, "button_release_event", body.positions[1])
    assert dragger.grab.particle is None and not body.fixed[1]
    np.testing.assert_allclose(body.velocities[1], 0.0, atol=1e-12)
    held = body.positions[1].copy()
    a = dragger.sim.dynamics.acceleration(body.positions, body.velocities)[1]
    assert np.linalg.norm(a) > 7.0  # the spring pulls hard: K · 80 px - g
    dragger.advance()
    # one frame later it has only started to move: Δx = ½ a dt² (velocity Verlet, dt = 1)
    np.testing.assert_allclose(body.positions[1] - held, 0.5 * a, rtol=1e-6)


def test_release_keeps_the_hands_velocity():
    dragger = viz.Dragger(gallery.two_particles(pull=0.0, damping=1.0))
    body = dragger.sim.body
    first = mouse(dragger, "button_press_event", body.positions[0])
    dragger.advance()
    second = mouse(dragger, "motion_notify_event", body.positions[0] + (-3.0, 4.0))
    dragger.advance()
    mouse(dragger, "button_release_event", body.positions[0])
    np.testing.assert_allclose(body.velocities[0], second - first, atol=1e-9)  # px per frame
    assert np.linalg.norm(body.velocities[0]) > 4.0


def test_other_buttons_and_clicks_outside_do_nothing():
    dragger = viz.Dragger(gallery.mesh())
    mouse(dragger, "button_press_event", dragger.sim.body.positions[0], button=3)
    assert dragger.grab.particle is None
    canvas = dragger.ax.figure.canvas
    canvas.callbacks.process("button_press_event", MouseEvent("button_press_event", canvas, 1, 1))
    assert dragger.grab.particle is None


def test_dragging_in_3d_moves_the_particle_under_the_mouse():
    sim = cloth.cloth()
    dragger = viz.Dragger(sim, view=(30.0, 20.0))
    body = sim.body
    particle = 44
    start = body.positions[particle].copy()
    canvas = dragger.ax.figure.canvas
    canvas.draw()  # as on screen: the 3-D projection is settled by the first draw
    screen = dragger._to_screen(start[None])[0]
    for name, offset in (("button_press_event", (0, 0)), ("motion_notify_event", (30, -20))):
        x, y = screen + offset
        canvas.callbacks.process(name, MouseEvent(name, canvas, x, y, button=1))
    assert dragger.grab.particle == particle
    dragger.advance()
    moved = dragger._to_screen(body.positions[particle][None])[0]
    np.testing.assert_allclose(moved, screen + np.array([30, -20]), atol=1.0)  # within a pixel


def test_grab_constraint_keeps_a_pinned_particle_pinned():
    body = msd.Body.from_arrays([[0.0, 0.0], [1.0, 0.0]], [[0, 1]], fixed=[True, False])
    sim = msd.Simulation(body, msd.VelocityVerlet(), 0.01)
    grab = msd.Grab()
    sim.constraints.append(grab)
    grab.hold(body, 0, target=(0.0, 0.5))
    sim.step()
    np.testing.assert_allclose(body.positions[0], (0.0, 0.5))
    grab.release()
    assert body.fixed[0]
    with pytest.raises(ValueError, match="does not exist"):
        grab.hold(body, 5)


def test_a_blow_up_stops_the_window_with_the_diagnosis():
    dragger = viz.Dragger(gallery.rope(stiffness=1.5, damping=1.0), steps_per_frame=50)
    dragger.advance()
    assert "stopped: simulation diverged" in dragger.ax.get_title()
    assert np.all(np.isfinite(dragger.sim.body.positions))


def test_show_without_a_display_says_so():
    with pytest.raises(RuntimeError, match="no display"):
        viz.show(gallery.mesh())


def test_live_view_shows_the_whole_box_and_says_how_to_drag():
    dragger = viz.Dragger(gallery.mesh())
    x_low, x_high = dragger.ax.get_xlim()
    y_low, y_high = dragger.ax.get_ylim()
    assert x_low < 0.0 and x_high > gallery.WIDTH and y_low < 0.0 and y_high > gallery.HEIGHT
    assert "drag" in dragger.ax.get_title() and "quit" in dragger.ax.get_title()
    assert dragger.drawing.springs.norm.vmax == viz.interactive.LIVE_STRAIN_LIMIT


def test_a_new_live_view_stops_the_previous_one(monkeypatch):
    monkeypatch.setattr(viz.interactive, "check_display", lambda: None)
    monkeypatch.setattr(plt, "show", lambda: None)
    first = viz.show(gallery.mesh())
    steps = first.sim.step_count
    second = viz.show(gallery.mesh())
    assert viz.interactive._running == [second]
    first.timer._on_timer()  # a stopped timer has no callbacks left to run
    assert first.sim.step_count == steps
    second.stop()


def test_a_paced_live_view_keeps_its_steps_per_second_whatever_a_frame_costs(monkeypatch):
    """A clock the test moves: frames of 0.1 s, 0.25 s and 1/60 s all give 60 steps a
    second; a frame that hung for 2 s steps a quarter second's worth and leaves no backlog."""
    now = [50.0]
    monkeypatch.setattr(viz.interactive, "perf_counter", lambda: now[0])
    dragger = viz.Dragger(gallery.mesh(), steps_per_second=60.0)

    def steps_over(frame_times):
        before = dragger.sim.step_count
        for frame_time in frame_times:
            now[0] += frame_time
            dragger.advance()
        return dragger.sim.step_count - before

    assert steps_over([0.0]) == 1  # the first frame
    assert steps_over([0.1] * 10) in (59, 60, 61)
    assert steps_over([0.25] * 4) in (59, 60, 61)
    assert steps_over([1 / 60] * 60) in (59, 60, 61)
    assert steps_over([2.0]) == 15
    assert steps_over([0.1]) == 6
