"""Simulation: steps a body in time and records what happened."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from . import equations
from .body import Body
from .constraint import Constraint, StepState
from .dynamics import Dynamics
from .energy import EnergyLedger, kinetic_energy
from .errors import SimulationDiverged, check_finite_array, check_positive, diagnose_divergence
from .forces import Force
from .integrators import Integrator, Verlet
from .kernels import StepEnd


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
    integrator step. Each step pins the fixed particles, keeps an energy
    ledger, and raises `SimulationDiverged` in the step where the state stops
    being finite or a spring is stretched past ``max_stretch`` times its rest length.
    ``kernel`` picks the spring kernel, "numba" or "numpy" (see `Dynamics`).
    ``ledger=False`` skips booking the energy each mechanism takes out (its cost
    matters for small bodies in contact); frames still record the energies, and
    every loss then shows as drift.
    """

    def __init__(
        self,
        body: Body,
        integrator: Integrator | None = None,
        dt: float = 1e-3,
        forces: Sequence[Force | Constraint] = (),
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
        for item in forces:
            if isinstance(item, Force):
                field_forces.append(item)
            elif isinstance(item, Constraint):
                self.constraints.append(item)
            else:
                raise TypeError(
                    f"{item!r} is neither a msdlab.Force (Gravity, SphereContact, ...) "
                    "nor a msdlab.Constraint (Ground, Drag, Walls, ...)"
                )
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

        The integrator's step, then: pin the fixed particles, apply the constraints,
        book the energy, check for divergence, and copy the new state into the body.
        The update loop of `Dynamics.advance` may have done the pinning, the finite
        check, the floor's search and the sum for the damping's work already
        (`kernels.StepEnd`); the rest is the same.
        """
        body, dt = self.body, self.dt
        x, v = body.positions, body.velocities
        self.dynamics.forget_last_state()
        end = self._step_end()
        self.dynamics.step_end = end
        try:
            result = self.integrator.step(x, v, dt, self.dynamics)
        except ValueError as error:
            if "read-only" in str(error) and end.arrays:
                raise TypeError(
                    f"{self.integrator!r}.step wrote into a read-only array: in a Simulation "
                    "the arrays dynamics.advance returns are read-only; return them as they "
                    "are, or compute new ones (x_new + ..., not x_new += ...)"
                ) from error
            raise
        finally:
            self.dynamics.step_end = None
        x_new, v_new = self._checked(result, x)
        ended = len(end.arrays) == 2 and end.arrays[0] is x_new and end.arrays[1] is v_new
        if ended:  # the constraints edit them
            x_new.flags.writeable = v_new.flags.writeable = True
        power = self.dynamics.dashpot_power(x, v) if self.ledger else 0.0
        fixed = body.fixed
        if not ended and fixed.any():
            x_new[fixed] = x[fixed]
            v_new[fixed] = 0.0
        energy_of = self._energy_of(x_new, v_new) if self.ledger else _unbooked
        state = StepState(body, x, v, x_new, v_new, self.time + dt, dt, energy_of)
        removed = []
        for i, constraint in enumerate(self.constraints):
            state.under = end.under if ended and i == 0 else None
            removed.append((constraint.ledger_name, constraint.apply(state)))
        floors = 0 if end.under is None else 1
        summed = ended and len(self.constraints) == floors  # no constraint but the floor
        if self.ledger:  # after the constraints: the integrator's damping works at the final v
            booked = self._dissipation(x, v, v_new, power, end if summed else None)
            for name, energy in removed:
                booked[name] = booked.get(name, 0.0) + energy
        else:
            booked = {}
        # a floor keeps finite values finite; other constraints may not: check after them
        self._check_divergence(x, x_new, v_new, end.finite if summed else None)
        x[...] = x_new
        v[...] = v_new
        self.time += dt
        self.step_count += 1
        for name, energy in booked.items():
            self.dissipated[name] += energy

    def _step_end(self) -> StepEnd:
        """What the step's update loop may do for this step: see `kernels.StepEnd`."""
        floor = self.constraints[0].floor(self.body) if self.constraints else None
        normal, height = (np.zeros(0), 0.0) if floor is None else self._checked_floor(floor)
        integrator = self.integrator
        damping = (
            self.ledger
            and type(integrator).dissipated_energy is Integrator.dissipated_energy
            and integrator.velocity_factor != 1.0
        )
        return StepEnd(normal, height, damping)

    def _checked_floor(self, floor: object) -> tuple[np.ndarray, float]:
        """A constraint's `Constraint.floor` as (unit normal (d,), height), or ValueError."""
        try:
            normal, height = floor  # type: ignore[misc]
            normal, height = np.asarray(normal, dtype=float), float(height)
        except (TypeError, ValueError):
            normal, height = np.zeros(0), math.nan
        if (
            normal.shape != (self.body.dim,)
            or not math.isfinite(height)
            or not abs(math.hypot(*normal) - 1.0) <= 1e-9  # False for NaN
        ):
            raise ValueError(
                f"{self.constraints[0]!r}.floor must return None or (unit normal of "
                f"{self.body.dim} numbers, height in m), got {floor!r}"
            )
        return normal, height

    def _dissipation(
        self,
        x: np.ndarray,
        v: np.ndarray,
        v_new: np.ndarray,
        dashpot_power: float,
        end: StepEnd | None = None,
    ) -> dict[str, float]:
        """Energy (J) the dashpots, the integrator's damping and dissipative forces take out
        in the step from (x, v) to velocities ``v_new``, by source. ``end``: the update
        loop summed the damping's work but over the particles under the floor."""
        dt, masses = self.dt, self.body.masses
        if end is not None and end.damping:
            rows = end.under if end.under is not None else slice(0)
            damping = (1.0 - self.integrator.velocity_factor) * end.damping_work
            damping += self.integrator.dissipated_energy(v[rows], masses[rows], v_new[rows])
        else:
            damping = self.integrator.dissipated_energy(v, masses, v_new)
        booked = {"dashpot": dashpot_power * dt, "integrator": damping}
        for force in self.forces:
            lost = force.dissipated_power(self.body, x, v)
            if lost:
                booked[force.ledger_name] = booked.get(force.ledger_name, 0.0) + lost * dt
        return booked

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
        end. ``callback(sim)`` is called after every step (e.g. a progress bar).
        """
        steps = self._count_steps(steps, duration)
        if isinstance(record_every, bool) or not isinstance(record_every, int) or record_every < 1:
            raise ValueError(f"record_every must be an integer >= 1, got {record_every!r}")
        start = dict(self.dissipated)
        ledger = EnergyLedger()
        frames: list[tuple[int, float, np.ndarray, np.ndarray | None]] = []

        def record() -> None:
            x, v = self.body.positions, self.body.velocities
            frames.append(
                (self.step_count, self.time, x.copy(), v.copy() if record_velocities else None)
            )
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

        record()
        try:
            for i in range(1, steps + 1):
                self.step()
                if i % record_every == 0 or i == steps:
                    record()
                if callback is not None:
                    callback(self)
        except SimulationDiverged as error:
            error.trajectory = self._trajectory(frames, ledger)
            raise
        return self._trajectory(frames, ledger)

    # ------------------------------------------------------------------ helpers
    def _count_steps(self, steps: int | None, duration: float | None) -> int:
        if (steps is None) == (duration is None):
            raise ValueError("give either steps=... or duration=... (in seconds), not both")
        if duration is not None:
            duration = float(duration)
            if not math.isfinite(duration) or duration < 0:
                raise ValueError(
                    f"duration must be a finite number of seconds >= 0, got {duration}"
                )
            return round(duration / self.dt)
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 0:
            raise ValueError(f"steps must be an integer >= 0, got {steps!r}")
        return int(steps)

    def _checked(self, result: object, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The integrator's (x, v) as fresh float arrays of the body's shape."""
        try:
            x_new, v_new = result  # type: ignore[misc]
        except (TypeError, ValueError):
            raise TypeError(
                f"{self.integrator!r}.step must return (x_new, v_new), got {type(result).__name__}"
            ) from None
        arrays = []
        for name, array in (("x_new", x_new), ("v_new", v_new)):
            array = np.asarray(array, dtype=float)
            if array.shape != x.shape:
                raise ValueError(
                    f"{self.integrator!r}.step returned {name} of shape {array.shape}; "
                    f"it must have the shape of the positions, {x.shape}"
                )
            arrays.append(array.copy() if np.shares_memory(array, x) else array)
        return arrays[0], arrays[1]

    def _energy_of(self, x: np.ndarray, v: np.ndarray) -> Callable[[np.ndarray], float]:
        """Energy (J) of some particles at (x, v): their kinetic and external potential
        energy plus the elastic energy of the springs touching them. The kinetic
        part uses the velocity at the time of x (see `Integrator.velocity_at_positions`)."""
        body, dynamics, integrator = self.body, self.dynamics, self.integrator
        last: list = [None, None]  # constraints ask before and after a change: find springs once
        synchronising = (
            type(integrator).velocity_at_positions is not Integrator.velocity_at_positions
        )

        def energy(particles: np.ndarray) -> float:
            if last[0] is not particles:
                last[:] = particles, body.springs_touching(particles)
            touching = last[1]
            u = v[particles]
            if synchronising:
                a = dynamics.acceleration_of(particles, x, v, touching)
                u = integrator.velocity_at_positions(u, a, self.dt)
            kinetic = equations.kinetic_energy(body.masses[particles], u)
            potential = sum(f.potential_energy(body, x, particles) for f in self.forces)
            return float(kinetic + potential + dynamics.elastic_energy(x, touching))

        return energy

    def _check_divergence(
        self, x: np.ndarray, x_new: np.ndarray, v_new: np.ndarray, finite: bool | None = None
    ) -> None:
        """Raise `SimulationDiverged` if the new state is not finite (``finite``, if the
        update loop checked) or a spring is stretched past ``max_stretch``."""
        if finite is None:
            finite = math.isfinite(float(x_new.sum()) + float(v_new.sum()))
        stretched = self.max_stretch is not None and self.dynamics.max_stretch > self.max_stretch
        if not finite or stretched:
            diagnosis = diagnose_divergence(
                self.body,
                self.integrator,
                self.dt,
                self.forces,
                self.initial_positions,
                x,
                x_new,
                v_new,
            )
            raise SimulationDiverged(self.step_count, self.time, diagnosis)

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
