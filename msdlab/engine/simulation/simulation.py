"""Simulation: steps a body in time and records what happened."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING

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

if TYPE_CHECKING:
    from ..backends.contract import SpringKernel


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
        if hasattr(self.dynamics.springs, "step") and self._device_steps(1, "step"):
            return  # a device backend's whole step
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
        sync: str = "step",
    ) -> Trajectory:
        """Run ``steps`` steps (or ``duration`` seconds) and return the recorded frames.

        A frame is recorded at the start, every ``record_every`` steps and at the
        end. ``callback(sim)`` is called after every step (e.g. a progress bar); it may edit
        the body. The body holds the state after every step, also when the run diverges;
        on a backend that runs whole steps on a device (Warp), at every frame and at the
        end (the state stays on the device in between). There, ``sync="frame"`` runs the
        steps between two frames as one captured frame (a CUDA graph on a GPU) whose ledger
        numbers come back once, not once a step (`_device_steps`).
        """
        steps = self._count_steps(steps, duration)
        if isinstance(record_every, bool) or not isinstance(record_every, int) or record_every < 1:
            raise ValueError(f"record_every must be an integer >= 1, got {shown(record_every)}")
        if sync not in ("step", "frame"):
            raise ValueError(f'sync must be "step" or "frame", got {shown(sync)}')
        batch = 1 if callback is not None else record_every  # steps a device may take at once
        ledger = EnergyLedger()
        frames: list[tuple[int, float, np.ndarray, np.ndarray | None]] = []
        record = partial(self._record, frames, ledger, dict(self.dissipated), record_velocities)
        record()
        try:
            done = 0
            while done < steps:
                done += self._steps(min(batch - done % batch, steps - done), sync)
                if done % record_every == 0 or done == steps:
                    record()
                if callback is not None:  # it sees the body's state, and may edit it
                    callback(self)
        except SimulationDiverged as error:
            error.trajectory = self._trajectory(frames, ledger)
            raise
        return self._trajectory(frames, ledger)

    def _steps(self, count: int, sync: str) -> int:
        """``count`` steps on a device backend where they run whole there
        (`_device_steps`), else one `step`; the number of steps taken."""
        if hasattr(self.dynamics.springs, "step") and self._device_steps(count, sync):
            return count
        self.step()
        return 1

    def _device_steps(self, count: int, sync: str) -> bool:
        """``count`` whole steps on the backend's device (`WarpKernel.step`, or one captured
        frame of them with ``sync="frame"``, `WarpKernel.frame`), from the body's state, which
        then adopts the device's: an update integrator (`Integrator.update_step`), uniform
        fields as forces, at most a ground plane as constraint. False, with nothing done, for
        any other step, or an update Warp cannot compile (the host steps it)."""
        kernel, plan = self.dynamics.springs, self._device_plan()
        if plan is None:
            return False
        kernel.load(self.body.positions, self.body.velocities)
        if sync == "frame" and count > 1:
            rows = kernel.frame(count, *plan)
            if rows is None:
                return False
            limit = np.inf if self.max_stretch is None else self.max_stretch
            if rows[:, 4].any() or (rows[:, 0] > limit).any():
                kernel.undo_frame()  # again from the frame's start, to stop where it blew up
                self._device_each(kernel, plan, count)
            else:
                for stretch, power, damping, ground, _ in rows.tolist():
                    self._book_device(stretch, power, damping, ground)
        elif not self._device_each(kernel, plan, count):
            return False
        self.body.store_state(*kernel.state())
        return True

    def _device_each(self, kernel: SpringKernel, plan: tuple, count: int) -> bool:
        """``count`` device steps, their sums read and booked after each; at a blow-up the body
        gets the state before it and `SimulationDiverged` is raised. False if not compiled."""
        for _ in range(count):
            sums = kernel.step(*plan)
            if sums is None:  # an update Warp cannot compile: the host's step (it said why)
                return False
            if (self.max_stretch is not None and sums.stretch > self.max_stretch) or not (
                sums.finite
            ):
                self._book_device(sums.stretch, sums.power, sums.damping, sums.ground)
                x, x_new, v_new = kernel.undo_step()
                self.body.store_state(*kernel.state())
                raise self._divergence(x, x_new, v_new)
            self._book_device(sums.stretch, sums.power, sums.damping, sums.ground)
        return True

    def _book_device(self, stretch: float, power: float, damping: float, ground: float) -> None:
        """A device step's sums: the dashpots' power (W) at its start, the integrator's
        damping work and the ground's energy (J), booked as `step` books them; the step's
        time."""
        if self.ledger:
            self.dissipated["dashpot"] += power * self._dt
            self.dissipated["integrator"] += damping
            for constraint in self.constraints:
                self.dissipated[constraint.ledger_name] += ground
        self.time += self._dt
        self.step_count += 1

    def _device_plan(self) -> tuple | None:
        """The arguments of the backend's whole ``step`` (see `_device_steps`), or None."""
        integrator, body = self.integrator, self.body
        found = integrator.update_step()
        booked = type(integrator).dissipated_energy is Integrator.dissipated_energy
        if found is None or not booked or len(self.constraints) > 1:
            return None
        field = np.zeros(body.dim)
        for force in self.dynamics.forces:
            g = force.uniform_acceleration(body)
            if g is None:
                return None
            field += g
        ground = self.constraints[0].plane(body) if self.constraints else None
        if self.constraints and ground is None:
            return None
        factor = integrator.velocity_factor if self.ledger else 1.0
        return found[0], self.dynamics.layout, field, self._dt, found[1], factor, ground

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
