"""A submission's integrator stepped by the engine through the grading sandbox: one round trip
per call, and the engine's own defaults run in the grader only where the submission kept them."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

import msdlab as msd
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
    expected = msd.energy.damping_work(masses, v, v_new, 0.5)
    assert expected > 0.0
    assert integrator.dissipated_energy(v, masses, v_new) == pytest.approx(expected, rel=1e-15)
    assert remote.task(5).Plain().dissipated_energy(v, masses, v_new) == 0.0
