"""Simulation: steps a body in time and records what happened."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np

from .. import equations
from ..dynamics import Dynamics
from ..integrators import Integrator, Verlet
from ..model.body import Body
from ..model.constraint import Constraint, StepState
from ..model.errors import SimulationDiverged, check_finite_array, check_positive, shown
from ..model.forces import Force
from ..model.units import SI, Units
from .energy import EnergyLedger, kinetic_energy
from .stability import describe_blowup


@dataclass
class Trajectory:
    """Frames recorded by `Simulation.run`: ``times`` (F,) s, ``positions`` (F, N, d) m,
    ``velocities`` (F, N, d) m/s or None, ``steps`` (F,) and the ``energies`` ledger."""

    body: Body
    dt: float
    steps: np.ndarray
    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray | None
    energies: EnergyLedger

    def __len__(self) -> int:
        return len(self.times)


def _unbooked(particles: np.ndarray) -> float:
    """The energy constraints see when the ledger is off: nothing is booked."""
    return 0.0


class Simulation:
    """A body, an integrator, a time step ``dt`` (s) and the forces acting on it.

    ``forces`` holds `Force` objects (gravity, contact, ...) and `Constraint`
    objects (ground, drag, walls, ...), applied in the given order after each
    integrator step; one of them alone needs no list. Each step keeps the fixed
    particles in place, keeps an energy ledger, and raises `SimulationDiverged` in the
    step where the state stops being finite or a spring is stretched past
    ``max_stretch`` times its rest length.
    ``kernel`` picks the spring kernel, "numba" or "numpy" (see `Dynamics`).
    ``ledger=False`` skips booking the energy each mechanism takes out (its cost
    matters for small bodies in contact); frames still record the energies, and
    every loss then shows as drift.
    """

    units: Units = SI  # what the numbers are in (views label with it); scenes may set it

    def __init__(
        self,
        body: Body,
        integrator: Integrator | None = None,
        dt: float = 1e-3,
        forces: Force | Constraint | Sequence[Force | Constraint] = (),
        *,
        max_stretch: float | None = 100.0,
        kernel: str | None = None,
        ledger: bool = True,
    ) -> None:
        if not isinstance(body, Body):
            raise TypeError(f"Simulation needs a msdlab.Body, got {type(body).__name__}")
        if len(body) == 0:
            raise ValueError("the body has no particles; add some with body.add_particle(...)")
        integrator = Verlet() if integrator is None else integrator
        if isinstance(integrator, type):
            raise TypeError(
                f"pass an integrator instance, e.g. {integrator.__name__}(), not the class"
            )
        if not isinstance(integrator, Integrator):
            raise TypeError(
                f"integrator must be a msdlab.Integrator, got {type(integrator).__name__}"
            )
        check_finite_array("positions", body.positions)
        check_finite_array("velocities", body.velocities)
        body.velocities[body.fixed] = 0.0
        self.body = body
        self.integrator = integrator
        self.dt = dt
        self.max_stretch = max_stretch
        self.ledger = ledger
        self.constraints: list[Constraint] = []
        field_forces: list[Force] = []
        for item in _as_list(forces):
            if isinstance(item, Force):
                field_forces.append(item)
            elif isinstance(item, Constraint):
                self.constraints.append(item)
            else:
                raise TypeError(_not_a_force(item))
            item.check(body)
        self.dynamics = Dynamics(body, field_forces, kernel=kernel)
        self.time = 0.0
        self.step_count = 0
        self.dissipated: dict[str, float] = defaultdict(float)
        self.initial_positions = body.positions.copy()

    @property
    def dt(self) -> float:
        """Time step (s)."""
        return self._dt

    @dt.setter
    def dt(self, value: float) -> None:
        self._dt = check_positive("dt", value, "The time step is in seconds, e.g. dt=1e-3.")

    @property
    def forces(self) -> list[Force]:
        """The force fields (not the constraints)."""
        return self.dynamics.forces

    # ------------------------------------------------------------------ stepping
    def step(self) -> None:
        """Advance the body by one step of ``dt``.

        Integrate, apply the constraints, book the energy each mechanism took out, check for
        divergence, and make the new state the body's: read ``body.positions`` and
        ``body.velocities`` again after a step, as arrays read before hold the old state.
        Edits of the body's state made before the call are where the step starts.

        The ledger books the dashpots and the dissipative forces at their power at the
        step's first pass over the springs, where it starts (`Step.powers`), the
        integrator's damping (`Integrator.dissipated_energy`, summed by the backend), and
        what each constraint returns.
        """
        body, dt, dynamics = self.body, self._dt, self.dynamics
        x, v = body.positions, body.velocities
        step = dynamics.step(self.integrator, x, v, dt)
        x_new, v_new = step.x, step.v
        energy_of = partial(self._energy, x_new, v_new) if self.ledger else _unbooked
        state = StepState(body, x, v, x_new, v_new, self.time + dt, dt, energy_of, dynamics.springs)
        removed = []
        for constraint in self.constraints:
            removed.append((constraint.ledger_name, constraint.apply(state)))
        if self.ledger:  # after the constraints: the integrator's damping works at the final v
            powers = dynamics.powers(x, v) if step.powers is None else step.powers
            for name, power in powers.items():
                self.dissipated[name] += power * dt
            self.dissipated["integrator"] += self.integrator.dissipated_energy(
                v, body.masses, v_new, kernel=dynamics.springs
            )
            for name, energy in removed:
                self.dissipated[name] += energy
        stretched = self.max_stretch is not None and step.stretch > self.max_stretch
        if stretched or not dynamics.springs.finite(x_new, v_new):
            raise self._divergence(x, x_new, v_new)
        body.store_state(x_new, v_new)
        self.time += dt
        self.step_count += 1

    def run(
        self,
        steps: int | None = None,
        duration: float | None = None,
        record_every: int = 1,
        record_velocities: bool = False,
        callback: Callable[[Simulation], None] | None = None,
    ) -> Trajectory:
        """Run ``steps`` steps (or ``duration`` seconds) and return the recorded frames.

        A frame is recorded at the start, every ``record_every`` steps and at the
        end. ``callback(sim)`` is called after every step (e.g. a progress bar); it may edit
        the body. The body holds the state after every step, also when the run diverges.
        """
        steps = self._count_steps(steps, duration)
        if isinstance(record_every, bool) or not isinstance(record_every, int) or record_every < 1:
            raise ValueError(f"record_every must be an integer >= 1, got {shown(record_every)}")
        ledger = EnergyLedger()
        frames: list[tuple[int, float, np.ndarray, np.ndarray | None]] = []
        record = partial(self._record, frames, ledger, dict(self.dissipated), record_velocities)
        record()
        try:
            for i in range(1, steps + 1):
                self.step()
                if i % record_every == 0 or i == steps:
                    record()
                if callback is not None:  # it sees the body's state, and may edit it
                    callback(self)
        except SimulationDiverged as error:
            error.trajectory = self._trajectory(frames, ledger)
            raise
        return self._trajectory(frames, ledger)

    def _record(
        self,
        frames: list[tuple[int, float, np.ndarray, np.ndarray | None]],
        ledger: EnergyLedger,
        start: dict[str, float],
        with_velocities: bool,
    ) -> None:
        """Add the body's state as a frame to ``frames`` (the velocities too if
        ``with_velocities``) and ``ledger`` (the energy taken out since ``start``, the
        dissipated energies by mechanism when the run started)."""
        x, v = self.body.positions, self.body.velocities
        frames.append((self.step_count, self.time, x.copy(), v.copy() if with_velocities else None))
        if self.step_count > 0:  # before the first step v is the user's v(t0)
            a = self.dynamics.acceleration(x, v)
            v = self.integrator.velocity_at_positions(v, a, self.dt)
        ledger.record(
            self.step_count,
            self.time,
            kinetic_energy(self.body, v),
            self.dynamics.elastic_energy(x),
            sum(f.potential_energy(self.body, x) for f in self.forces),
            {k: e - start.get(k, 0.0) for k, e in self.dissipated.items()},
        )

    # ------------------------------------------------------------------ helpers
    def _count_steps(self, steps: int | None, duration: float | None) -> int:
        if steps is None and duration is None:
            raise ValueError(
                "say how long to run: steps=... (a number of steps) or duration=... (in "
                "seconds), e.g. sim.run(steps=1000) or sim.run(duration=2.0)"
            )
        if steps is not None and duration is not None:
            raise ValueError("give either steps=... or duration=... (in seconds), not both")
        if duration is not None:
            duration = float(duration)
            if not math.isfinite(duration) or duration < 0:
                raise ValueError(
                    f"duration must be a finite number of seconds >= 0, got {duration}"
                )
            return round(duration / self.dt)
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 0:
            raise ValueError(f"steps must be an integer >= 0, got {shown(steps)}")
        return int(steps)

    def _energy(self, x: np.ndarray, v: np.ndarray, particles: np.ndarray) -> float:
        """Energy (J) of some particles at (x, v): their kinetic and external potential
        energy plus the elastic energy of the springs touching them. The kinetic
        part uses the velocity at the time of x (see `Integrator.velocity_at_positions`)."""
        body, dynamics, integrator = self.body, self.dynamics, self.integrator
        touching = body.springs_touching(particles)
        a = dynamics.acceleration_of(particles, x, v, touching)
        u = integrator.velocity_at_positions(v[particles], a, self._dt)
        kinetic = equations.kinetic_energy(body.masses[particles], u)
        potential = sum(f.potential_energy(body, x, particles) for f in self.forces)
        return float(kinetic + potential + dynamics.elastic_energy(x, touching))

    def _divergence(
        self, x: np.ndarray, x_new: np.ndarray, v_new: np.ndarray
    ) -> SimulationDiverged:
        """The error for a step from positions x to a state (x_new, v_new) that is not finite
        or stretches a spring past ``max_stretch`` times its rest length, with its diagnosis."""
        body, integrator, dt, forces = self.body, self.integrator, self._dt, self.forces
        blowup = (self.initial_positions, x, x_new, v_new)
        diagnosis = describe_blowup(body, integrator, dt, forces, *blowup)
        return SimulationDiverged(self.step_count, self.time, diagnosis)

    def _trajectory(self, frames: list, ledger: EnergyLedger) -> Trajectory:
        velocities = (
            None if not frames or frames[0][3] is None else np.array([f[3] for f in frames])
        )
        return Trajectory(
            body=self.body,
            dt=self.dt,
            steps=np.array([f[0] for f in frames]),
            times=np.array([f[1] for f in frames]),
            positions=np.array([f[2] for f in frames]),
            velocities=velocities,
            energies=ledger,
        )

    def __repr__(self) -> str:
        items = [*self.forces, *self.constraints]
        return (
            f"<Simulation {self.body!r}, {self.integrator!r}, dt={self.dt:g} s, "
            f"t={self.time:g} s, forces={items}>"
        )


def _not_a_force(item: object) -> str:
    """Why ``item`` in ``forces`` is neither a force nor a constraint, and what to give."""
    if isinstance(item, type) and issubclass(item, (Force, Constraint)):
        example = item.example or f"msd.{item.__name__}(...)"
        return f"{item.__name__} is a class; create one: {example}"
    return (
        f"forces holds a {type(item).__name__}: neither a msdlab.Force (Gravity, "
        "SphereContact, ...) nor a msdlab.Constraint (Ground, Drag, Walls, ...)"
    )


def _as_list(forces: object) -> list:
    """The ``forces`` argument as a list; one force or constraint alone is a list of one."""
    if isinstance(forces, (Force, Constraint)):
        return [forces]
    try:
        return list(forces)
    except TypeError:
        raise TypeError(
            "forces must be a list of msdlab.Force and msdlab.Constraint objects, e.g. "
            f"[msd.Gravity((0, -9.81, 0)), msd.Ground()], got a {type(forces).__name__}"
        ) from None
