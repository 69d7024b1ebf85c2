"""The live widget's model without a browser: what it sends, what the page's requests do."""

import re
import time

import numpy as np
import pytest

import msdlab as msd
from msdlab import viz
from msdlab.scenes import SCENES, gallery
from msdlab.viz.widget import LiveView, energies


def ask(view: LiveView, **content) -> None:
    """A request from the page (done at once: no stepping thread runs)."""
    view._on_message(view, content, [])


def test_the_page_gets_the_body_and_float32_positions():
    sim = gallery.mesh()
    view = LiveView(sim)
    assert view.scene["dim"] == 2 and len(view.scene["colours"]) == 64
    np.testing.assert_array_equal(
        np.frombuffer(view.positions, np.float32).reshape(-1, 2), sim.body.positions
    )
    pairs = np.frombuffer(view.springs, np.int32).reshape(-1, 2)
    np.testing.assert_array_equal(pairs[:, 0], sim.body.edges().a)
    assert len(view.scene["world"]["edges"]) == 4  # the gallery's walls


def test_a_3d_scene_stands_on_its_floor_with_y_up():
    view = LiveView(SCENES["jelly-cube"].build(size=3))
    assert view.scene["up"] == 1  # gravity along -y
    assert len(view.scene["world"]["edges"]) == 18  # the floor's grid


def test_the_pace_is_the_scenes_and_the_speed_scales_it():
    view = LiveView(gallery.two_particles(), steps_per_second=60)
    assert view.advance(0.5, budget=60) == 30
    view.speed = 2.0
    assert view.advance(0.5, budget=60) == 60
    physical = LiveView(msd.Simulation(msd.Body.from_arrays([[0.0, 0.0]], []), dt=0.01))
    assert physical.advance(0.1, budget=60) == 10  # real time: 1/dt steps a second


def test_at_a_step_a_frame_each_frame_on_the_beat_steps_once():
    # the thread's frames stand for their beats' times: none steps twice or not at all
    # (a state that repeats the one before is a picture the eye does not see move)
    view = LiveView(gallery.mesh(), steps_per_second=60)
    beat, steps = view._clock, []
    for _ in range(300):
        before = view.sim.step_count
        view.frame(beat := beat + 1 / 60)
        steps.append(view.sim.step_count - before)
    assert steps == [1] * 300


def test_a_hands_move_is_stepped_at_once_and_the_pace_kept():
    view = LiveView(gallery.mesh(), steps_per_second=60)
    assert view.advance(0.0) == 0  # half a step owed at the start (`PHASE`)
    ask(view, type="grab", particle=0, target=[0.0, 0.0])
    assert view._moved
    assert view.advance(0.0, early=True) == 1  # the step the hand waits for, now
    assert view.advance(0.0, early=True) == 0  # one step ahead of the pace at most
    assert view.advance(0.5 / 60) == 0  # the step taken early is not done again
    assert view.advance(1 / 60) == 1


def in_and_out(view: LiveView) -> tuple[float, float]:
    """The energy in the body plus all taken out, and the hand's work so far."""
    e = energies(view.sim, {})
    in_body = e["kinetic"] + e["elastic"] + e["gravitational"] + e["other"]
    return in_body + sum(e["dissipated"].values()), -e["dissipated"].get("hand", 0.0)


def test_a_hands_circle_arriving_in_bursts_is_booked_as_its_work():
    # the page's moves, a frame apart, reach the kernel three in a message, the kernel's
    # frames a little off the page's: each step still moves the held particle by the
    # hand's move of a frame, and the total moves by less than 1 % of the hand's work
    view = LiveView(gallery.mesh(), steps_per_second=60)
    view._thread = True  # the page's requests wait for the next frame, as they do running
    x = view.sim.body.positions
    particle = int(np.argmax(x[:, 0] - x[:, 1]))
    centre, now = x[particle].copy(), view._clock
    start = in_and_out(view)
    ask(view, type="grab", particle=particle, target=centre.tolist(), time=0.0)
    path = []
    for k in range(1, 121):  # twice round a 60 px circle in 2 s
        angle = 4 * np.pi * k / 120
        target = centre + 60.0 * np.array([np.cos(angle) - 1.0, np.sin(angle)])
        path.append([1000 * k / 60, *target])
        if k % 3 == 0:  # the page sends the moves of up to 100 ms in one message
            ask(view, type="move", path=path)
            path = []
            view.frame(now := now + 1 / 60 + 0.004 * np.sin(k))
            view.frame(now := now + 1 / 60)
            view.frame(now := now + 1 / 60)
    ask(view, type="release")
    for _ in range(120):
        view.frame(now := now + 1 / 60)
    assert view.grab.particle is None
    total, work = np.subtract(in_and_out(view), start)
    assert work > 1000.0
    assert abs(total) < 0.01 * work  # before: 2.5 %, a step carried three moves, then none


def test_the_hands_moves_are_played_back_at_their_pace_before_it_lets_go():
    sim = gallery.mesh(gravity=0.0)
    view = LiveView(sim, steps_per_second=60)
    view._thread = True  # the page's requests wait for the next frame, as they do running
    start, now = sim.body.positions[0].copy(), view._clock
    ask(view, type="grab", particle=0, target=start.tolist(), time=0.0)
    for k in (1, 2):  # a frame apart on the page, arriving together with the release
        ask(view, type="move", path=[[1000 * k / 60, *(start + (5.0 * k, 0.0))]])
    ask(view, type="release")
    view.frame(now := now + 1 / 60)
    np.testing.assert_allclose(sim.body.positions[0], start + (5.0, 0.0))  # the first move
    view.frame(now := now + 1 / 60)
    np.testing.assert_allclose(sim.body.positions[0], start + (10.0, 0.0))
    assert view.grab.particle == 0  # held until the playback reached the hand
    view.frame(now := now + 1 / 60)
    assert view.grab.particle is None and not sim.body.fixed[0]


def test_grab_move_release_keeps_the_hands_velocity():
    sim = gallery.mesh(gravity=0.0)
    view = LiveView(sim, steps_per_second=60)
    start = sim.body.positions[0].copy()
    ask(view, type="grab", particle=0, target=start.tolist(), time=0.0)
    ask(view, type="move", path=[[1000 / 60, *(start + (10.0, 0.0))]])
    view.advance(1 / 60)
    np.testing.assert_allclose(sim.body.positions[0], start + (10.0, 0.0))
    ask(view, type="release")
    assert view.grab.particle is None and not sim.body.fixed[0]
    np.testing.assert_allclose(sim.body.velocities[0], (10.0, 0.0))  # px per frame


def test_sliders_change_what_the_engine_uses_between_steps():
    sim = gallery.mesh()
    view = LiveView(sim)
    names = [s["name"] for s in view.settings]
    assert names == ["stiffness", "damping", "gravity", "dt"]
    ask(view, type="set", name="stiffness", value=0.2)
    np.testing.assert_allclose(sim.body.edges().stiffness, 0.2)
    ask(view, type="set", name="gravity", value=0.3)
    np.testing.assert_allclose(sim.forces[0].g, (0.0, -0.3))
    ask(view, type="set", name="damping", value=0.0)
    ask(view, type="set", name="dt", value=0.5)
    assert sim.dt == 0.5
    assert next(c for c in sim.constraints if isinstance(c, msd.Drag)).rate == 0.0


def test_a_scene_setting_rebuilds_the_scene_and_says_so():
    view = LiveView(SCENES["mesh"].build(), scene=SCENES["mesh"])
    spacing = next(s for s in view.settings if s["name"] == "spacing")
    assert spacing["rebuild"] and "rebuilds" in spacing["label"]
    old = view.sim
    ask(view, type="set", name="spacing", value=40.0)
    assert view.sim is not old
    assert np.ptp(view.sim.body.positions[:, 0]) == pytest.approx(9 * 40.0)
    assert next(s for s in view.settings if s["name"] == "spacing")["value"] == 40.0


def test_the_energy_in_the_body_is_the_ledgers_total():
    sim = SCENES["jelly-cube"].build(size=3)
    view = LiveView(sim)
    for _ in range(5):
        view.advance(0.01)
    energy = energies(sim, {}, level=0.25)
    g = sim.forces[0].g[1]  # along -y
    assert energy["zero"] == pytest.approx(-g * 0.25 * np.sum(sim.body.masses))
    in_body = energy["kinetic"] + energy["elastic"] + energy["gravitational"] + energy["other"]
    in_body += energy["zero"]  # the ledger counts gravitational energy from y = 0
    assert in_body == pytest.approx(sim.run(steps=0).energies.total[0], rel=1e-12)
    assert set(energy["dissipated"]) == set(sim.dissipated)


def test_a_blow_up_stops_the_view_with_the_diagnosis():
    sim = gallery.mesh()
    view = LiveView(sim, steps_per_second=60)
    ask(view, type="set", name="stiffness", value=50.0)
    view.advance(1.0, budget=60)
    assert not view.running
    assert "diverged" in view.error.lower() or "stretch" in view.error.lower()
    steps = sim.step_count
    view.frame()
    assert sim.step_count == steps  # stopped


def test_step_pauses_and_reset_goes_back_to_the_start():
    sim = gallery.mesh()
    view = LiveView(sim)
    start = sim.body.positions.copy()
    ask(view, type="step")
    assert not view.running and sim.step_count == 1
    ask(view, type="reset")
    np.testing.assert_array_equal(sim.body.positions, start)
    assert sim.step_count == 0 and sim.time == 0.0


def test_a_step_after_reset_starts_from_the_start():
    """Reset writes the start into the body's arrays; the next step steps from there."""
    sim = gallery.mesh()
    view = LiveView(sim)
    for _ in range(3):
        ask(view, type="step")
    ask(view, type="reset")
    ask(view, type="step")
    fresh = gallery.mesh()
    fresh.step()
    np.testing.assert_array_equal(sim.body.positions, fresh.body.positions)
    np.testing.assert_array_equal(sim.body.velocities, fresh.body.velocities)


def test_the_thread_steps_at_its_own_pace_and_stops():
    view = viz.widget.live(gallery.mesh(), steps_per_second=60)
    try:
        time.sleep(0.5)
    finally:
        view.stop()
    steps = view.sim.step_count
    assert 5 <= steps <= 40
    time.sleep(0.1)
    assert view.sim.step_count == steps


def test_the_replay_page_holds_positions_and_asks_the_network_for_nothing(tmp_path):
    run = gallery.mesh().run(steps=60, record_every=10)
    page = viz.save_animation(run, tmp_path / "mesh.html", time_unit="frames").read_text()
    assert "data:image/png" not in page
    assert not re.search(r"(src|href)=\"?https?:", page)
    assert '"frames": "' in page and "export async function replay" in page


def sent_by(view: LiveView) -> list[tuple[dict, list]]:
    """The messages ``view`` sends the page from now on: (content, buffers)."""
    messages: list[tuple[dict, list]] = []
    view.send = lambda content, buffers=None: messages.append((content, buffers))
    return messages


def test_each_state_is_one_message_with_its_energies_inside():
    sim = gallery.mesh()
    view = LiveView(sim, steps_per_second=60)
    messages = sent_by(view)
    for _ in range(viz.widget.ENERGY_EVERY):
        view.frame()
    assert len(messages) == viz.widget.ENERGY_EVERY  # one a state, no pair
    content, (positions,) = messages[-1]
    np.testing.assert_array_equal(
        np.frombuffer(positions, np.float32).reshape(-1, 2), sim.body.positions.astype(np.float32)
    )
    assert content["energy"]["time"] == sim.time and content["status"].startswith("t = ")
    assert "energy" not in messages[0][0]  # the energies every few states only


def test_the_view_sends_as_many_states_as_the_page_draws_frames():
    view = LiveView(gallery.mesh(), steps_per_second=60)
    ask(view, type="frames", rate=37.5)
    assert view.send_rate == 37.5
    ask(view, type="frames", rate=500.0)
    assert view.send_rate == viz.widget.FRAME_RATE


def test_a_view_that_cannot_keep_pace_says_so():
    sim = SCENES["jelly-cube"].build(size=3)
    view = LiveView(sim)  # real time
    view.advance(8.0, budget=60)  # 20 steps of 0.4 s
    assert "pace" not in view.status_line()
    view.advance(8.0, budget=0.0)  # no time to step
    assert "pace 0.00 × real time (the engine cannot keep up)" in view.status_line()
    gallery_view = LiveView(gallery.mesh(), steps_per_second=60)
    gallery_view.advance(0.5, budget=0.0)
    assert "pace 0.00 × 60 steps/s" in gallery_view.status_line()


def test_energies_are_in_the_scenes_units():
    assert LiveView(gallery.mesh()).scene["energy_unit"] == "px²/frame²"
    assert LiveView(gallery.mesh()).scene["time_unit"] == "frame"
    assert LiveView(SCENES["jelly-cube"].build(size=3)).scene["energy_unit"] == "J"
    assert LiveView(gallery.mesh(), energy_unit="kJ").scene["energy_unit"] == "kJ"
