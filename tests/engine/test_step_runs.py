"""The integrator's `step` is what runs, on every kernel; a user's integrator runs the same way."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.dynamics import Dynamics


def grid() -> msd.Body:
    body = msd.Body.grid((4, 3, 3), spacing=0.1, stiffness=40.0, neighbours=(1, 2, 3))
    body.springs_as_edges()  # values of their own per spring
    body.set_springs(slice(None, None, 2), damping=0.2)
    body.velocities[:] = np.random.default_rng(0).normal(size=body.positions.shape)
    body.fixed[0] = True
    return body


@pytest.mark.parametrize(
    "integrator", [msd.Verlet(0.01), msd.SymplecticEuler(), msd.RK4()], ids=repr
)
def test_step_is_entered_once_per_step(
    integrator: msd.Integrator, kernel: str, monkeypatch
) -> None:
    calls = []
    original = type(integrator).step

    def counted(self, x, v, dt, dynamics):
        calls.append(dynamics.kernel)
        return original(self, x, v, dt, dynamics)

    monkeypatch.setattr(type(integrator), "step", counted)
    msd.Simulation(grid(), integrator, forces=[msd.Gravity((0, -9.81, 0))]).run(steps=10)
    assert calls == [kernel] * 10


def damped_update(x: float, v: float, a: float, dt: float, lam: float) -> tuple[float, float]:
    """A user's eq. (1.4), written as the building block `Dynamics.advance` takes."""
    old = x - v * dt
    new = (2.0 - lam) * x - (1.0 - lam) * old + a * dt**2
    return new, (new - x) / dt


class UserVerlet(msd.Integrator):
    """A student's Verlet with damping, stepping through `Dynamics.advance`."""

    def __init__(self, damping: float) -> None:
        self.damping = damping

    def step(self, x, v, dt, dynamics):
        return dynamics.advance(damped_update, x, v, dt, self.damping)


class ArrayVerlet(msd.Integrator):
    """The same scheme written with `Dynamics.acceleration` and whole arrays."""

    def __init__(self, damping: float) -> None:
        self.damping = damping

    def step(self, x, v, dt, dynamics):
        a = dynamics.acceleration(x, v)
        return damped_update(x, v, a, dt, self.damping)


def test_a_users_integrator_matches_the_engines() -> None:
    results = []
    for integrator in (msd.Verlet(0.05), UserVerlet(0.05), ArrayVerlet(0.05)):
        body = grid()
        msd.Simulation(body, integrator, forces=[msd.Gravity((0, -9.81, 0))]).run(steps=20)
        results.append(body.positions.copy())
    np.testing.assert_array_equal(results[1], results[0])  # the same function, the same bits
    np.testing.assert_allclose(results[2], results[0], rtol=1e-12, atol=1e-12)


def print_update(x: float, v: float, a: float, dt: float) -> tuple[float, float]:
    """An update numba cannot compile (it builds a Python object): it runs on arrays instead."""
    note = {"why": object()}
    del note
    return x + dt * v, v + dt * a


def test_an_update_numba_cannot_compile_still_runs(kernel: str) -> None:
    body = grid()
    dynamics = Dynamics(body)
    x, v = body.positions, body.velocities
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        x_new, v_new = dynamics.advance(print_update, x, v, 1e-3)
    assert [w.category for w in caught] == ([RuntimeWarning] if kernel == "numba" else [])
    a = dynamics.acceleration(x, v)
    np.testing.assert_allclose(x_new, x + 1e-3 * v, rtol=1e-15)
    np.testing.assert_allclose(v_new, v + 1e-3 * a, rtol=1e-12)
