"""A submission's integrator stepped by the engine through the grading sandbox: one round trip
per call, and the engine's own defaults run in the grader only where the submission kept them."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.equations import damping_work
from msdlab.instructor.judging.sandbox import RemoteImplementation

INTEGRATORS = """
import msdlab as msd

class Plain(msd.Integrator):
    def step(self, x, v, dt, dynamics):
        v_new = v + dt * dynamics.acceleration(x, v)
        return x + dt * v_new, v_new

class Own(Plain):
    def velocity_at_positions(self, v, a, dt):
        return 2.0 * v

    def dissipated_energy(self, v, masses, v_new=None):
        return 1.5

class Patched(Plain):
    def __init__(self):
        self.velocity_at_positions = lambda v, a, dt: 3.0 * v

class Factor(Plain):
    velocity_factor = 0.5

class Spoiler(msd.Integrator):
    def step(self, x, v, dt, dynamics):
        first = dynamics.acceleration(x, v)
        first[:] = 0.0  # spoils the array it was given
        return x + dt * v, v + dt * dynamics.acceleration(x, v)

class Mover(msd.Integrator):
    def step(self, x, v, dt, dynamics):
        x += 0.25  # moves the positions it was given, then asks
        return x + dt * v, v + dt * dynamics.acceleration(x, v)
"""


@pytest.fixture(scope="module")
def remote(serve_task) -> RemoteImplementation:
    return serve_task("task5.py", INTEGRATORS)


def counted(remote: RemoteImplementation, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The ops of the requests the grader sends from now on."""
    ops: list[str] = []
    request = remote.sandbox.request

    def counting(message: dict, *args, **kwargs):
        ops.append(message["op"])
        return request(message, *args, **kwargs)

    monkeypatch.setattr(remote.sandbox, "request", counting)
    return ops


def test_a_simulation_step_is_one_round_trip(remote, monkeypatch):
    integrator = remote.task(5).Plain()
    body = msd.Body.grid((2, 2, 2), 0.5, neighbours=(1,))
    simulation = msd.Simulation(body, integrator, 0.01, [msd.Gravity((0.0, -1.0, 0.0))])
    ops = counted(remote, monkeypatch)
    run = simulation.run(steps=20)
    assert sorted(ops) == ["call"] * 20 + ["inherited"]  # the defaults ran here, asked once
    here: dict = {}
    exec(textwrap.dedent(INTEGRATORS), here)  # the same class, run in this process
    body = msd.Body.grid((2, 2, 2), 0.5, neighbours=(1,))
    local = msd.Simulation(body, here["Plain"](), 0.01, [msd.Gravity((0.0, -1.0, 0.0))])
    assert np.array_equal(run.positions, local.run(steps=20).positions)


def served_calls(remote: RemoteImplementation, monkeypatch: pytest.MonkeyPatch) -> list[dict]:
    """The calls the submission makes back to the grader from now on."""
    calls: list[dict] = []
    serve = remote.sandbox._serve

    def counting(request: dict) -> bytes:
        if request["op"] == "call":
            calls.append(request)
        return serve(request)

    monkeypatch.setattr(remote.sandbox, "_serve", counting)
    return calls


def local_step(name: str, x, v, dt, dynamics):
    """The step of the submission's class ``name`` run in this process."""
    here: dict = {}
    exec(textwrap.dedent(INTEGRATORS), here)
    return here[name]().step(x.copy(), v.copy(), dt, dynamics)


def step_case():
    body = msd.Body.grid((2, 2, 2), 0.5, neighbours=(1, 2))
    x = body.positions + 0.05 * np.random.default_rng(3).standard_normal(body.positions.shape)
    v = np.random.default_rng(4).standard_normal(x.shape)
    return msd.Dynamics(body, [msd.Gravity((0.0, -1.0, 0.0))]), x, v


def test_the_acceleration_at_the_steps_state_comes_with_the_step(remote, monkeypatch):
    """The grader sends the engine's a(x, v) with the step: the submission's calls at that
    state need no round trip, and each gets its own copy (spoiling one spoils no other)."""
    dynamics, x, v = step_case()
    calls = served_calls(remote, monkeypatch)
    x_new, v_new = remote.task(5).Spoiler().step(x.copy(), v.copy(), 0.1, dynamics)
    assert calls == []
    expected = local_step("Spoiler", x, v, 0.1, dynamics)
    assert np.array_equal(x_new, expected[0]) and np.array_equal(v_new, expected[1])
    assert not np.array_equal(v_new, v)  # the second answer was not the spoiled first


def test_an_acceleration_asked_at_another_state_is_the_engines_there(remote, monkeypatch):
    dynamics, x, v = step_case()
    calls = served_calls(remote, monkeypatch)
    x_new, v_new = remote.task(5).Mover().step(x.copy(), v.copy(), 0.1, dynamics)
    assert len(calls) == 1  # a call back: x was moved after the grader sent a(x, v)
    expected = local_step("Mover", x, v, 0.1, dynamics)
    assert np.array_equal(x_new, expected[0]) and np.array_equal(v_new, expected[1])


@pytest.mark.parametrize(("name", "factor", "lost"), [("Own", 2.0, 1.5), ("Patched", 3.0, 0.0)])
def test_methods_the_submission_replaced_run_in_the_sandbox(remote, name, factor, lost):
    integrator = getattr(remote.task(5), name)()
    v = np.ones((2, 3))
    assert np.array_equal(integrator.velocity_at_positions(v, np.zeros((2, 3)), 0.1), factor * v)
    assert integrator.dissipated_energy(v, np.ones(2), v) == lost


def test_the_engines_damping_work_uses_the_submissions_velocity_factor(remote):
    v, v_new, masses = np.ones((2, 3)), np.full((2, 3), 0.25), np.array([1.0, 2.0])
    integrator = remote.task(5).Factor()
    assert integrator.velocity_factor == 0.5
    expected = damping_work(masses, v, v_new, 0.5)
    assert expected > 0.0
    assert integrator.dissipated_energy(v, masses, v_new) == pytest.approx(expected, rel=1e-15)
    assert remote.task(5).Plain().dissipated_energy(v, masses, v_new) == 0.0
