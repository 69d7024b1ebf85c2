"""The live view's instruments and export, read from Python as a student would: the
stopwatch against the simulated time, the trace's period against 2π√(m/k), the ruler,
the hanging lines, the arrows, gravity presets, and an export read back with numpy."""

import time

import numpy as np
import pytest

import msdlab as msd
from msdlab.scenes import SCENES
from msdlab.viz.widget import LiveView, live

MASS, STIFFNESS, REST, G = 0.5, 20.0, 1.0, 9.81


def spring_mass(dt: float = 1e-3, pulled: float = 0.1) -> msd.Simulation:
    """A mass hung from a pinned particle by one spring, pulled ``pulled`` below equilibrium."""
    equilibrium = REST + MASS * G / STIFFNESS
    body = msd.Body.from_arrays(
        [[0.0, 0.0], [0.0, -equilibrium - pulled]],
        [[0, 1]],
        masses=MASS,
        fixed=[True, False],
        stiffness=STIFFNESS,
        rest_lengths=[REST],
    )
    return msd.Simulation(body, msd.Verlet(), dt=dt, forces=[msd.Gravity((0.0, -G))])


def ask(view: LiveView, **content) -> None:
    """A request from the page (done at once: no stepping thread runs)."""
    view._on_message(view, content, [])


def run_for(view: LiveView, seconds: float) -> None:
    """Step ``seconds`` of simulated time at real time pace, as the thread would."""
    for _ in range(round(seconds / (1 / 60))):
        view.advance(1 / 60, budget=60)
        view.publish()


def test_the_stopwatch_reads_the_simulated_time_it_ran():
    view = LiveView(spring_mass())
    ask(view, type="stopwatch", action="start")
    run_for(view, 0.5)
    ask(view, type="stopwatch", action="stop")
    run_for(view, 0.25)  # stopped: not counted
    assert view.stopwatch.reading == pytest.approx(0.5, abs=1e-9)
    view.stopwatch.start()
    run_for(view, 0.25)
    assert view.stopwatch.reading == pytest.approx(0.75, abs=1e-9)
    assert view.sim.time == pytest.approx(1.0, abs=1e-9)
    ask(view, type="stopwatch", action="reset")
    assert view.stopwatch.reading == 0.0 and view.stopwatch.running
    with pytest.raises(ValueError, match="no button 'lap'"):
        view.press_stopwatch("lap")


def test_the_page_gets_the_readings_of_the_instruments_turned_on():
    view = LiveView(spring_mass())
    view.publish()
    assert view.readings == {}  # nothing turned on: nothing measured
    view.toggle("stopwatch")
    view.toggle("ruler", True)
    view.stopwatch.start()
    run_for(view, 0.1)
    assert set(view.readings) == {"time", "stopwatch", "ruler"}
    assert view.readings["stopwatch"]["reading"] == pytest.approx(0.1, abs=1e-9)
    view.toggle("stopwatch")
    view.toggle("ruler", False)
    view.publish()
    assert view.readings == {}  # all off: the page is told once
    with pytest.raises(ValueError, match="no instrument 'protractor': choose one of stopwatch"):
        view.toggle("protractor")


def test_the_traces_period_is_the_spring_masss():
    view = LiveView(spring_mass(dt=1e-3))
    assert view.trace.particle == 1 and view.trace.axis == 1  # the hung mass, vertically
    run_for(view, 3.0)
    expected = 2 * np.pi * np.sqrt(MASS / STIFFNESS)  # 0.993 s: three periods traced
    assert view.trace.period() == pytest.approx(expected, rel=1e-4)
    view.toggle("trace")
    view.publish()
    trace = view.readings["trace"]
    assert trace["period"] == view.trace.period()
    t, x, v = np.array(trace["points"]).T
    assert t[-1] == pytest.approx(view.sim.time) and len(t) <= 240
    assert np.ptp(x) == pytest.approx(0.2, rel=1e-2)  # the swing: ±0.1 m
    assert np.max(np.abs(v)) == pytest.approx(0.1 * 2 * np.pi / expected, rel=1e-2)


def test_a_trace_of_a_body_at_rest_has_no_period():
    view = LiveView(spring_mass(pulled=0.0))
    run_for(view, 1.0)
    assert view.trace.period() is None


def test_the_ruler_and_the_trace_follow_the_particles_taken_in_hand():
    sim = SCENES["rope"].build()
    view = LiveView(sim)
    assert view.ruler_ends[0] == 0  # from the pinned end
    ask(view, type="grab", particle=5, target=sim.body.positions[5].tolist())
    ask(view, type="release")
    ask(view, type="grab", particle=9, target=sim.body.positions[9].tolist())
    assert view.ruler_ends == (5, 9) and view.trace.particle == 9
    view.toggle("ruler")
    view.publish()
    expected = np.linalg.norm(sim.body.positions[5] - sim.body.positions[9])
    assert view.readings["ruler"]["distance"] == pytest.approx(expected, rel=1e-12)


def test_the_lines_are_where_the_hung_mass_is_at_rest_and_unstretched():
    view = LiveView(spring_mass())
    view.toggle("lines")
    view.publish()
    lines = view.readings["lines"]
    assert lines["natural"] == pytest.approx([0.0, -REST])
    assert lines["equilibrium"] == pytest.approx([0.0, -REST - MASS * G / STIFFNESS])
    view.set_gravity("Moon")
    ask(view, type="grab", particle=1, target=[0.3, -1.0])  # held in hand: still shown
    view.publish()
    assert view.readings["lines"]["equilibrium"][1] == pytest.approx(
        -REST - MASS * 1.62 / STIFFNESS
    )
    mesh = LiveView(SCENES["mesh"].build())
    mesh.toggle("lines")
    mesh.publish()
    assert mesh.readings["lines"] is None  # no mass hung by a single spring


def test_the_arrows_are_the_velocity_and_the_net_force():
    view = LiveView(spring_mass(pulled=0.1))
    view.toggle("arrows")
    view.publish()
    arrows = view.readings["arrows"]
    assert arrows["velocity"] == pytest.approx([0.0, 0.0])
    assert arrows["force"] == pytest.approx([0.0, STIFFNESS * 0.1])  # pulled 0.1 below rest


def test_gravity_presets_are_in_the_scenes_units():
    view = LiveView(spring_mass())
    assert view.presets == pytest.approx({"Earth": 9.81, "Moon": 1.62, "Jupiter": 24.79, "zero": 0})
    view.set_gravity("Jupiter")
    assert view.sim.forces[0].g == pytest.approx([0.0, -24.79])
    mesh = LiveView(SCENES["mesh"].build())  # in pixels and frames
    g = np.linalg.norm(mesh.sim.forces[0].g)
    assert mesh.presets["Earth"] == pytest.approx(g)
    assert mesh.presets["Moon"] == pytest.approx(g * 1.62 / 9.81)
    with pytest.raises(ValueError, match="choose one of Earth, Moon, Jupiter, zero"):
        view.set_gravity("Mars")
    weightless = LiveView(msd.Simulation(msd.Body.from_arrays([[0.0, 0.0]]), dt=0.01))
    with pytest.raises(ValueError, match="no gravity to set"):
        weightless.set_gravity("Moon")


def test_an_export_reads_back_with_numpy(tmp_path):
    view = LiveView(spring_mass())
    run_for(view, 0.5)
    npz = np.load(view.export(tmp_path / "run.npz"))
    frames = len(npz["time"])
    assert frames == 31 and npz["time"][-1] == pytest.approx(view.sim.time)  # 30 + the start
    assert npz["positions"].shape == npz["velocities"].shape == (frames, 2, 2)
    np.testing.assert_array_equal(npz["positions"][-1], view.sim.body.positions)
    ledger = view.sim.run(steps=0).energies
    assert npz["total"][-1] - npz["total"][0] == pytest.approx(0.0, abs=1e-4)
    in_body = npz["kinetic"] + npz["elastic"] + npz["gravitational"] + npz["other"]
    assert npz["total"] == pytest.approx(in_body + sum(npz[k] for k in npz if "dissipated" in k))
    assert ledger.kinetic[0] == pytest.approx(npz["kinetic"][-1], rel=1e-9)
    assert str(npz["time_unit"]) == "s" and str(npz["energy_unit"]) == "J"

    table = np.genfromtxt(view.export(tmp_path / "run.csv"), delimiter=",", names=True)
    assert len(table) == frames
    np.testing.assert_allclose(table["time_s"], npz["time"], rtol=1e-15)
    np.testing.assert_allclose(table["y_1"], npz["positions"][:, 1, 1], rtol=1e-15)
    np.testing.assert_allclose(table["vy_1"], npz["velocities"][:, 1, 1], rtol=1e-15)
    np.testing.assert_allclose(table["total_J"], npz["total"], rtol=1e-15)
    with pytest.raises(ValueError, match=r"name a \.csv file"):
        view.export(tmp_path / "run.xlsx")


def test_every_state_the_page_is_sent_is_exported(tmp_path, monkeypatch):
    view = LiveView(spring_mass())  # its first state is sent at once
    sent = []
    monkeypatch.setattr(view, "send", lambda content, buffers: sent.append(buffers[0]))
    for _ in range(12):  # a frame every 1/60 s, as the stepping thread sends them
        view._clock -= 1 / 60
        view.frame()
    npz = np.load(view.export(tmp_path / "run.npz"))
    shown = [np.frombuffer(state, np.float32).reshape(2, 2) for state in sent]
    assert len(npz["time"]) == 1 + len(shown) and np.all(np.diff(npz["time"]) > 0)
    np.testing.assert_array_equal(npz["positions"][1:].astype(np.float32), shown)
    assert npz["total"] == pytest.approx(npz["total"][0], abs=1e-4)  # a ledger for each


def test_reset_starts_the_recording_and_the_stopwatch_over():
    view = LiveView(spring_mass())
    view.stopwatch.start()
    run_for(view, 0.2)
    ask(view, type="reset")
    view.publish()
    assert len(view.recording.frames) == 1 and view.stopwatch.reading == 0.0
    assert view.trace.particle == 1


def test_the_page_can_download_the_run(monkeypatch):
    view = LiveView(spring_mass())
    run_for(view, 0.1)
    sent = []
    monkeypatch.setattr(view, "send", lambda content, buffers: sent.append((content, buffers)))
    ask(view, type="export", format="csv")
    ((content, [data]),) = sent
    assert content == {"type": "export", "name": "msdlab-run.csv"}
    assert data.decode().startswith("time (s),kinetic (J),")


def test_the_run_exports_while_the_view_runs(tmp_path):
    view = live(spring_mass())
    try:
        time.sleep(0.5)
        for _ in range(10):  # while the stepping thread adds states
            path = view.export(tmp_path / "run.npz")
    finally:
        view.stop()
    times = np.load(path)["time"]
    assert len(times) >= 3 and np.all(np.diff(times) > 0)
