"""The end of a step done in the update loop (`kernels.StepEnd`): the same step as the
Simulation's per-array passes (pinning, the floor, the finite check), bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

import msdlab as msd
from msdlab.compiled import kernel as numba_kernel
from msdlab.kernels import StepEnd

GRAVITY = (0.0, -9.81, 0.0)


def copying(integrator: type[msd.Integrator]) -> type[msd.Integrator]:
    """``integrator`` returning copies of its arrays: the Simulation then does the end of
    each step with its per-array passes, the reference."""

    class Copying(integrator):  # type: ignore[misc, valid-type]
        def step(self, x, v, dt, dynamics):
            x_new, v_new = super().step(x, v, dt, dynamics)
            return x_new.copy(), v_new.copy()

    return Copying


def falling_body(dim: int, size: int) -> msd.Body:
    """A grid just above a floor at 0.1 m, moving randomly, with dashpots and fixed particles."""
    neighbours = (1, 2, 3) if dim == 3 else (1, 2)
    body = msd.Body.grid((size,) * dim, spacing=0.1, stiffness=200.0, neighbours=neighbours)
    body.spring_damping[:] = 0.05
    body.positions[:, 1] += 0.15
    body.velocities[:] = np.random.default_rng(1).normal(size=body.velocities.shape)
    body.fixed[:: 7 * size] = True
    return body


def run(integrator: msd.Integrator, body: msd.Body, constraints: list, steps: int = 200):
    """Run and return the simulation and the `StepEnd` of each step."""
    gravity = msd.Gravity(GRAVITY[: body.dim])
    sim = msd.Simulation(body, integrator, dt=1e-3, forces=[gravity, *constraints])
    ends: list[StepEnd] = []
    make_end = sim._step_end
    sim._step_end = lambda: ends.append(make_end()) or ends[-1]  # type: ignore[method-assign]
    sim.run(steps=steps)
    return sim, ends


@pytest.mark.parametrize("threads", [False, True], ids=["one thread", "threads"])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("normal", [None, (0.1, 1.0, 0.05)], ids=["y up", "tilted"])
@pytest.mark.parametrize("scheme", [msd.Verlet, msd.SymplecticEuler, msd.ExplicitEuler])
@pytest.mark.parametrize("friction", [0.0, 0.4])
def test_the_loop_ends_the_step_as_the_simulation_does(
    scheme, friction: float, normal, dim: int, threads: bool, kernel: str, monkeypatch
) -> None:
    if threads:
        if kernel == "numpy":
            pytest.skip("threads are the numba kernel's")
        for limit in ("PARALLEL_MIN_PARTICLES", "PARALLEL_MIN_SPRINGS", "PARALLEL_MIN_GATHERED"):
            monkeypatch.setattr(numba_kernel, limit, 10)
    normal = None if normal is None else normal[:dim]
    integrator = (lambda cls: cls(0.01)) if scheme is msd.Verlet else (lambda cls: cls())
    searched: list[bool] = []  # did the floor get the particles the loop found?
    apply = msd.Ground.apply
    monkeypatch.setattr(
        msd.Ground,
        "apply",
        lambda self, state: searched.append(state.under is not None) or apply(self, state),
    )
    results = []
    for cls in (scheme, copying(scheme)):
        body = falling_body(dim, 9 if dim == 3 else 20)
        floor = msd.Ground(height=0.1, normal=normal, friction=friction)
        sim, ends = run(integrator(cls), body, [floor])
        results.append((body.positions, body.velocities, dict(sim.dissipated), ends))
    (x, v, booked, ends), (x_ref, v_ref, booked_ref, _) = results
    np.testing.assert_array_equal(x, x_ref)
    np.testing.assert_array_equal(v, v_ref)
    damping = booked.pop("integrator"), booked_ref.pop("integrator")  # summed in another order
    assert booked == booked_ref
    assert booked["ground"] != 0.0  # the floor acted
    fused = kernel == "numba"  # the loop ended the steps of the first run, not the reference's
    assert searched == [fused] * len(ends) + [False] * len(ends)
    assert any(end.under is not None and len(end.under) for end in ends) == fused
    if scheme is msd.Verlet:  # λ's work, summed by the loop but under the floor
        assert damping[0] == pytest.approx(damping[1], rel=1e-12, abs=0.0)
        assert all(end.damping and (end.damping_work > 0) == fused for end in ends)
    else:
        assert damping == (0.0, 0.0)
        assert not any(end.damping for end in ends)


def test_more_constraints_after_the_floor(kernel: str) -> None:
    results = []
    for cls in (msd.Verlet, copying(msd.Verlet)):
        body = falling_body(3, 8)
        constraints = [msd.Ground(height=0.1, friction=0.2), msd.Drag(0.5)]
        sim, _ = run(cls(0.02), body, constraints)
        results.append((body.positions, body.velocities, dict(sim.dissipated)))
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1], results[1][1])
    assert results[0][2] == results[1][2]  # with drag after it, λ's work is summed afterwards


class Poison(msd.Constraint):
    """A broken constraint: it makes one velocity NaN at step 5."""

    def __init__(self) -> None:
        self.calls = 0

    def apply(self, state) -> float:
        self.calls += 1
        if self.calls == 5:
            state.v[3, 0] = np.nan
        return 0.0


@pytest.mark.parametrize("first", [True, False], ids=["floor first", "floor last"])
def test_a_constraint_making_nan_is_caught_in_its_step(first: bool) -> None:
    floor, poison = msd.Ground(height=-10.0), Poison()
    body = falling_body(3, 5)
    sim = msd.Simulation(body, msd.Verlet(), forces=[floor, poison] if first else [poison, floor])
    with pytest.raises(msd.SimulationDiverged) as raised:
        sim.run(steps=10)
    assert raised.value.step == 4  # the fifth step, counted from 0
    assert np.isfinite(body.velocities).all()  # the body keeps the last finite state


@pytest.mark.filterwarnings("ignore:.*encountered:RuntimeWarning")  # the reference's inf - inf
def test_the_loop_catches_a_step_that_blows_up() -> None:
    body = falling_body(3, 5)
    body.velocities[2, 1] = 1e306
    sim = msd.Simulation(body, msd.SymplecticEuler(), dt=1e3, forces=[msd.Ground(height=-1.0)])
    sim.max_stretch = None  # only the finite check can catch it
    with pytest.raises(msd.SimulationDiverged) as raised:
        sim.run(steps=3)
    assert raised.value.step == 0
    assert np.isfinite(body.positions).all()


class InPlace(msd.Integrator):
    """Writes into the arrays `Dynamics.advance` returned (which a Simulation's end owns)."""

    def step(self, x, v, dt, dynamics):
        x_new, v_new = dynamics.advance(msd.integrators.symplectic_euler_update, x, v, dt)
        v_new *= 0.99
        return x_new, v_new


def test_writing_into_advances_arrays_is_explained(kernel: str) -> None:
    sim = msd.Simulation(falling_body(2, 4), InPlace(), forces=[msd.Ground()])
    if kernel == "numpy":  # nothing was done in a loop: the arrays are the integrator's
        sim.run(steps=2)
        return
    with pytest.raises(TypeError, match="x_new \\+ \\.\\.\\., not x_new \\+="):
        sim.run(steps=2)


class SpringyFloor(msd.Ground):
    """A floor with its own `apply`: the update loop must not search for it."""

    def apply(self, state) -> float:
        return super().apply(state)


def test_a_floor_with_its_own_apply_is_searched_by_itself() -> None:
    body = falling_body(3, 4)
    assert msd.Ground().floor(body) is not None
    assert SpringyFloor().floor(body) is None
    sim, ends = run(msd.Verlet(), body, [SpringyFloor(height=0.1)], steps=150)
    assert all(end.under is None for end in ends)
    assert sim.dissipated["ground"] != 0.0


class OwnLedger(msd.Verlet):
    """A Verlet that books its damping its own way: the loop must not sum it for it."""

    def dissipated_energy(self, v, masses, v_new=None) -> float:
        return 1.0


@pytest.mark.parametrize("ledger", [True, False])
def test_damping_is_summed_only_for_the_ledger_of_a_velocity_factor(ledger: bool) -> None:
    for integrator, summed in ((msd.Verlet(0.1), ledger), (OwnLedger(0.1), False)):
        body = falling_body(3, 4)
        gravity = msd.Gravity(GRAVITY)
        sim = msd.Simulation(body, integrator, forces=[gravity], ledger=ledger)
        assert sim._step_end().damping == summed
    sim.run(steps=3)
    assert sim.dissipated.get("integrator", 0.0) == (3.0 if ledger else 0.0)


class BadFloor(msd.Constraint):
    """A constraint whose floor is not a plane of the body's dimension."""

    def __init__(self, floor) -> None:
        self.plane = floor

    def floor(self, body):
        return self.plane

    def apply(self, state) -> float:
        return 0.0


@pytest.mark.parametrize(
    "floor", [((0.0, 1.0), 0.0), ((0.0, 2.0, 0.0), 0.0), ((0.0, 1.0, 0.0), np.nan), "flat"]
)
def test_a_floor_that_is_not_a_plane_is_refused(floor) -> None:
    sim = msd.Simulation(falling_body(3, 3), msd.Verlet(), forces=[BadFloor(floor)])
    with pytest.raises(ValueError, match="floor must return None or \\(unit normal of 3 numbers"):
        sim.step()
