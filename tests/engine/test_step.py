"""The guarantees of `Simulation.step`, through the public step: fixed particles stay put,
the constraints and the ledger see the integrator's new state whoever owns its arrays, a
state that stops being finite is caught in its step, and the body holds the new state."""

from __future__ import annotations

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.backends.numba import kernel as numba_kernel
from msdlab.engine.equations import damping_work

GRAVITY = (0.0, -9.81, 0.0)


def copying(integrator: type[msd.Integrator]) -> type[msd.Integrator]:
    """``integrator`` returning copies of its arrays: a step that cannot depend on who owns
    the arrays `Dynamics.advance` returns, the reference."""

    class Copying(integrator):  # type: ignore[misc, valid-type]
        def step(self, x, v, dt, dynamics):
            x_new, v_new = super().step(x, v, dt, dynamics)
            return x_new.copy(), v_new.copy()

    return Copying


def falling_body(dim: int, size: int) -> msd.Body:
    """A grid just above a floor at 0.1 m, moving randomly, with dashpots and fixed particles."""
    neighbours = (1, 2, 3) if dim == 3 else (1, 2)
    body = msd.Body.grid((size,) * dim, spacing=0.1, stiffness=200.0, neighbours=neighbours)
    body.set_springs(damping=0.05)
    body.positions[:, 1] += 0.15
    body.velocities[:] = np.random.default_rng(1).normal(size=body.velocities.shape)
    body.fixed[:: 7 * size] = True
    return body


def run(integrator: msd.Integrator, body: msd.Body, constraints: list, steps: int = 200):
    gravity = msd.Gravity(GRAVITY[: body.dim])
    sim = msd.Simulation(body, integrator, dt=1e-3, forces=[gravity, *constraints])
    sim.run(steps=steps)
    return sim


@pytest.mark.parametrize("threads", [False, True], ids=["one thread", "threads"])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("normal", [None, (0.1, 1.0, 0.05)], ids=["y up", "tilted"])
@pytest.mark.parametrize("scheme", [msd.Verlet, msd.SymplecticEuler, msd.ExplicitEuler])
@pytest.mark.parametrize("friction", [0.0, 0.4])
def test_the_step_does_not_depend_on_who_owns_the_arrays(
    scheme, friction: float, normal, dim: int, threads: bool, kernel: str, monkeypatch
) -> None:
    if threads:
        if kernel == "numpy":
            pytest.skip("threads are the numba kernel's")
        for limit in ("PARALLEL_MIN_PARTICLES", "PARALLEL_MIN_SPRINGS", "PARALLEL_MIN_GATHERED"):
            monkeypatch.setattr(numba_kernel, limit, 10)
    normal = None if normal is None else normal[:dim]
    integrator = (lambda cls: cls(0.01)) if scheme is msd.Verlet else (lambda cls: cls())
    results = []
    for cls in (scheme, copying(scheme)):
        body = falling_body(dim, 9 if dim == 3 else 20)
        fixed = body.positions[body.fixed].copy()
        floor = msd.Ground(height=0.1, normal=normal, friction=friction)
        sim = run(integrator(cls), body, [floor])
        np.testing.assert_array_equal(body.positions[body.fixed], fixed)  # pinned exactly
        assert not body.velocities[body.fixed].any()
        results.append((body.positions, body.velocities, dict(sim.dissipated)))
    (x, v, booked), (x_ref, v_ref, booked_ref) = results
    np.testing.assert_array_equal(x, x_ref)
    np.testing.assert_array_equal(v, v_ref)
    assert booked == booked_ref
    assert booked["ground"] != 0.0  # the floor acted
    assert (booked["integrator"] > 0.0) == (scheme is msd.Verlet)


def test_more_constraints_after_the_floor() -> None:
    results = []
    for cls in (msd.Verlet, copying(msd.Verlet)):
        body = falling_body(3, 8)
        sim = run(cls(0.02), body, [msd.Ground(height=0.1, friction=0.2), msd.Drag(0.5)])
        results.append((body.positions, body.velocities, dict(sim.dissipated)))
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1], results[1][1])
    assert results[0][2] == results[1][2]


def test_the_body_holds_the_new_state_after_each_step() -> None:
    body = falling_body(3, 4)
    sim = msd.Simulation(body, msd.Verlet(0.01), forces=[msd.Gravity(GRAVITY)])
    x, v = body.positions.copy(), body.velocities.copy()
    x_new, v_new = msd.Verlet(0.01).step(x, v, sim.dt, sim.dynamics)
    free = ~body.fixed
    sim.step()
    np.testing.assert_array_equal(body.positions[free], x_new[free])
    np.testing.assert_array_equal(body.velocities[free], v_new[free])
    assert sim.step_count == 1 and sim.time == sim.dt


class Reusing(msd.Integrator):
    """Velocity Verlet writing into two buffers of its own, the same ones every step."""

    def __init__(self) -> None:
        self.buffers: tuple[np.ndarray, ...] = ()

    def step(self, x, v, dt, dynamics):
        if not self.buffers:
            self.buffers = (np.empty_like(x), np.empty_like(v))
        x_new, v_new = self.buffers
        a = dynamics.acceleration(x, v)
        np.add(v, 0.5 * dt * a, out=v_new)
        np.add(x, dt * v_new, out=x_new)
        v_new += 0.5 * dt * dynamics.acceleration(x_new, v + dt * a)
        return x_new, v_new


def test_an_integrator_reusing_its_buffers_steps_as_one_making_new_arrays() -> None:
    bodies = [falling_body(3, 4), falling_body(3, 4)]
    sims = [
        msd.Simulation(body, scheme, forces=[msd.Gravity(GRAVITY), msd.Ground()])
        for body, scheme in zip(bodies, (Reusing(), msd.VelocityVerlet()))
    ]
    for sim in sims:
        sim.run(steps=30)
    np.testing.assert_array_equal(bodies[0].positions, bodies[1].positions)
    np.testing.assert_array_equal(bodies[0].velocities, bodies[1].velocities)
    assert sims[0].dissipated["ground"] == sims[1].dissipated["ground"]


def test_a_particle_pinned_between_steps_stays_put() -> None:
    body = falling_body(3, 4)
    sim = msd.Simulation(body, msd.Verlet(0.01), forces=[msd.Gravity(GRAVITY)])
    sim.run(steps=3)
    body.fixed[5] = True  # in the body's arrays of now, taken over from the kernel
    where = body.positions[5].copy()
    sim.run(steps=3)
    np.testing.assert_array_equal(body.positions[5], where)
    np.testing.assert_array_equal(body.velocities[5], 0.0)


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


@pytest.mark.filterwarnings("ignore:.*encountered:RuntimeWarning")  # inf - inf
def test_a_step_that_blows_up_is_caught() -> None:
    body = falling_body(3, 5)
    body.velocities[2, 1] = 1e306
    sim = msd.Simulation(body, msd.SymplecticEuler(), dt=1e3, forces=[msd.Ground(height=-1.0)])
    sim.max_stretch = None  # only the finite check can catch it
    with pytest.raises(msd.SimulationDiverged) as raised:
        sim.run(steps=3)
    assert raised.value.step == 0
    assert np.isfinite(body.positions).all()


class InPlace(msd.Integrator):
    """Writes into the arrays `Dynamics.advance` returned."""

    def step(self, x, v, dt, dynamics):
        x_new, v_new = dynamics.advance(msd.SymplecticEuler.update, x, v, dt)
        v_new *= 0.99
        return x_new, v_new


class Fresh(msd.Integrator):
    """`InPlace` computing new arrays instead."""

    def step(self, x, v, dt, dynamics):
        x_new, v_new = dynamics.advance(msd.SymplecticEuler.update, x, v, dt)
        return x_new, v_new * 0.99


def test_an_integrator_may_write_into_the_arrays_advance_returns() -> None:
    bodies = [falling_body(2, 4), falling_body(2, 4)]
    for body, integrator in zip(bodies, (InPlace(), Fresh())):
        msd.Simulation(body, integrator, forces=[msd.Ground()]).run(steps=20)
    np.testing.assert_array_equal(bodies[0].positions, bodies[1].positions)


class SpringyFloor(msd.Ground):
    """A floor with its own `apply`."""

    def apply(self, state) -> float:
        return 2.0 * super().apply(state)


def test_a_floor_with_its_own_apply_is_used() -> None:
    sims = [
        run(msd.Verlet(), falling_body(3, 4), [cls(height=0.1)], steps=150)
        for cls in (msd.Ground, SpringyFloor)
    ]
    np.testing.assert_array_equal(sims[0].body.positions, sims[1].body.positions)
    assert sims[1].dissipated["ground"] == 2.0 * sims[0].dissipated["ground"] != 0.0


class OwnLedger(msd.Verlet):
    """A Verlet that books its damping its own way."""

    def dissipated_energy(self, v, masses, v_new=None, *, kernel=None) -> float:
        return 1.0


@pytest.mark.parametrize("ledger", [True, False])
def test_an_integrator_books_its_own_damping(ledger: bool) -> None:
    body = falling_body(3, 4)
    sim = msd.Simulation(body, OwnLedger(0.1), forces=[msd.Gravity(GRAVITY)], ledger=ledger)
    sim.run(steps=3)
    assert sim.dissipated.get("integrator", 0.0) == (3.0 if ledger else 0.0)


@pytest.mark.parametrize("kernel", ["numba", "numpy"])
def test_the_integrators_damping_is_summed_by_the_simulations_backend(kernel: str) -> None:
    """`Integrator.dissipated_energy` by default: the work of the velocity factor, summed by
    the backend the simulation passes it, the same number as `equations.damping_work`."""
    gravity = msd.Gravity(GRAVITY)
    sim = msd.Simulation(falling_body(3, 4), msd.Verlet(0.1), forces=[gravity], kernel=kernel)
    sums = []
    work = sim.dynamics.springs.damping_work

    def summing(*arguments: object) -> float:
        sums.append(work(*arguments))
        return sums[-1]

    sim.dynamics.springs.damping_work = summing
    sim.run(steps=3)
    assert len(sums) == 3
    assert sim.dissipated["integrator"] == pytest.approx(sum(sums), rel=1e-15) != 0.0
    v, v_new = np.ones((4, 3)), np.full((4, 3), 0.5)
    masses = np.arange(1.0, 5.0)
    expected = damping_work(masses, v, v_new, 0.9)
    for backend in (None, sim.dynamics.springs):
        lost = msd.Verlet(0.1).dissipated_energy(v, masses, v_new, kernel=backend)
        assert lost == pytest.approx(expected, rel=1e-14)


def edit_in_place(body: msd.Body) -> None:
    """What the live view's drag and reset do: write into the body's arrays."""
    body.positions[3] += (0.0, 0.5, 0.0)
    body.velocities[3] = (1.0, 0.0, 0.0)


def assign_whole(body: msd.Body) -> None:
    """What the scenes and notebooks do: assign whole arrays."""
    body.positions = body.positions + (0.0, 0.5, 0.0)
    body.velocities = np.zeros_like(body.velocities)


@pytest.mark.parametrize("edit", [edit_in_place, assign_whole])
@pytest.mark.parametrize("call", ["step", "run", "run with frames apart"])
def test_edits_of_the_body_between_calls_are_where_the_next_step_starts(edit, call) -> None:
    """The backend holds the state while it steps; the body's state, edited between two
    public calls, is what the next call steps from, whichever call came before."""
    bodies = [falling_body(3, 4), falling_body(3, 4)]
    sims = [
        msd.Simulation(body, msd.Verlet(0.01), forces=[msd.Gravity(GRAVITY)]) for body in bodies
    ]
    for sim in sims:
        if call == "step":
            sim.step()
        else:
            sim.run(steps=4, record_every=1 if call == "run" else 3)
    edit(bodies[0])
    reference = falling_body(3, 4)
    reference.positions, reference.velocities = bodies[1].positions, bodies[1].velocities
    edit(reference)
    x, v = reference.positions.copy(), reference.velocities.copy()
    x_new, v_new = msd.Verlet(0.01).step(x, v, sims[0].dt, sims[0].dynamics)
    sims[0].step()
    free = ~bodies[0].fixed
    np.testing.assert_array_equal(bodies[0].positions[free], x_new[free])
    np.testing.assert_array_equal(bodies[0].velocities[free], v_new[free])


def test_a_run_stores_its_state_in_the_body_at_frames_for_callbacks_and_at_the_end() -> None:
    bodies = [falling_body(3, 4), falling_body(3, 4)]
    sims = [
        msd.Simulation(body, msd.Verlet(0.01), forces=[msd.Gravity(GRAVITY)]) for body in bodies
    ]
    seen = []

    def watch(sim: msd.Simulation) -> None:
        seen.append(sim.body.positions.copy())
        if sim.step_count == 2:
            sim.body.positions[3, 1] += 1.0  # an edit in a callback is where the next step starts

    run = sims[0].run(steps=7, record_every=3, callback=watch)
    sims[1].run(steps=7, record_every=3)
    body = bodies[0]
    np.testing.assert_array_equal(body.positions, run.positions[-1])
    np.testing.assert_array_equal(body.positions, seen[-1])
    assert len(seen) == 7 and not np.array_equal(seen[0], seen[1])
    lifted = body.positions[:, 1] - bodies[1].positions[:, 1]
    assert lifted[3] == pytest.approx(1.0, abs=0.05)


def test_a_run_that_diverges_leaves_the_last_good_state_in_the_body() -> None:
    body = falling_body(3, 4)
    sim = msd.Simulation(body, msd.Verlet(0.0), dt=0.04, forces=[msd.Gravity(GRAVITY)])
    with pytest.raises(msd.SimulationDiverged) as diverged:
        sim.run(steps=2000, record_every=1000)
    assert np.isfinite(body.positions).all() and np.isfinite(body.velocities).all()
    assert sim.step_count == diverged.value.step > 1
    assert not np.array_equal(body.positions, diverged.value.trajectory.positions[0])
