"""Constraints: rules applied after each integrator step (floor, drag, walls, driven particles).

A constraint edits the new positions and velocities in place and returns the
energy it removed (J; negative when it put energy in) for the energy ledger.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from ..engine import equations
from ..engine.model.body import Body
from ..engine.model.constraint import Constraint, StepState
from ..engine.model.errors import check_non_negative
from ..engine.simulation import energy

_UP = {2: np.array([0.0, 1.0]), 3: np.array([0.0, 1.0, 0.0])}  # the default ground normal, +y


def lead(state: StepState, particles: np.ndarray, target: np.ndarray) -> float:
    """Move fixed ``particles`` to ``target`` (m) with the velocity of that move,
    v = (target - x_old) / dt, and return the energy removed (J; negative: put in).

    The driver's work over the step is the change of the energy involving the
    particles, E(target, v) - E(x_old, v_old): the integrator kept them where they were
    and stopped them, and that stop is the driver's doing as much as the move. Their
    neighbours are taken at the middle of the step, ½ (x_old + x): the work is then the
    midpoint rule of ∫ F·dx along the move, exact to second order in dt (with the
    neighbours at the step's end it falls short by a term of first order, 6 % of a hand's
    work on the gallery's mesh).
    """
    ends = state.body.neighbours(particles)
    now = state.x[ends]
    state.x[ends] = 0.5 * (state.x_old[ends] + now)
    state.v[particles] = state.v_old[particles]
    before = state.energy_of(particles)
    state.x[particles] = target
    state.v[particles] = (target - state.x_old[particles]) / state.dt
    removed = before - state.energy_of(particles)
    state.x[ends] = now
    return removed


class Ground(Constraint):
    """The template's floor: particles that end a step below the plane are put back on it.

    Fixed particles are left where they are. The plane holds the points p with
    p·normal = height (normal defaults to +y,
    the brief's floor y = 0; use ``normal=(0, 0, 1)`` for z-up scenes). A clamped
    particle keeps its tangential velocity (times 1 - ``friction``) and its
    normal velocity becomes the displacement it really made over the step / dt,
    which is what position Verlet implies: no bounce, no sticking.

    The ledger books the work of the contact force, not the energy difference
    across the clamp (`msdlab.engine.equations.ground_contact`): the clamp gives each
    particle a kick Δv along the normal, and the force m·Δv/dt works at the
    particle's mean velocity over the step. A particle held at rest gets no
    work; one that lands loses energy, and with Verlet the ground never puts
    any in (the mean normal velocity is (x(t+dt) - x(t-dt))·n/2dt ≤ 0 when
    x(t+dt) is on the plane and x(t-dt) was not below it). A body at rest on the
    ground books nothing. Friction books the kinetic energy it takes out of the tangential velocity.

    The step's backend does it (`SpringKernel.ground_clamp`): `backends.numpy.ground_clamp` on
    numpy arrays, the readable reference, or one compiled pass over the particles.
    """

    ledger_name = "ground"
    example = "msd.Ground()"

    def __init__(
        self, height: float = 0.0, normal: Sequence[float] | None = None, friction: float = 0.0
    ) -> None:
        self.height = float(height)
        self.normal = None if normal is None else np.asarray(normal, dtype=float)
        if self.normal is not None:
            length = np.linalg.norm(self.normal)
            if self.normal.ndim != 1 or not np.isfinite(length) or length == 0:
                raise ValueError(f"ground normal must be a non-zero vector, got {normal!r}")
            self.normal = self.normal / length
        check_non_negative("ground friction", friction)
        if friction > 1:
            raise ValueError(f"ground friction is a fraction in [0, 1], got {friction}")
        self.friction = float(friction)

    def normal_of(self, body: Body) -> np.ndarray:
        """The floor's unit normal (d,) for ``body``: ``normal``, or +y by default."""
        return np.array(_UP[body.dim], dtype=float) if self.normal is None else self.normal

    def check(self, body: Body) -> None:
        if self.normal is not None and len(self.normal) != body.dim:
            raise ValueError(
                f"ground normal has {len(self.normal)} components but the body is {body.dim}-D"
            )

    def plane(self, body: Body) -> tuple[np.ndarray, float, float] | None:
        """The floor's normal for ``body``, its height and friction, for a device backend's
        own step; None for a subclass with its own `apply`, which must run as written."""
        if type(self).apply is not Ground.apply:
            return None
        return np.asarray(self.normal_of(body)), self.height, self.friction

    def apply(self, state: StepState) -> float:
        """The backend's `ground_clamp` (`backends.numpy.ground_clamp` on arrays) on the step."""
        body = state.body
        n = _UP[body.dim] if self.normal is None else self.normal
        arrays = (state.x, state.v, state.x_old, state.v_old, body.masses, body.fixed, n)
        return state.kernel.ground_clamp(*arrays, self.height, state.dt, self.friction)

    def __repr__(self) -> str:
        return f"Ground(height={self.height:g}, normal={self.normal}, friction={self.friction:g})"


class Drag(Constraint):
    """Air drag solved exactly over each step: v ← v·exp(-rate·dt), rate in 1/s.

    Being the exact solution of dv/dt = -rate·v it is stable at any dt (unlike
    the force -c·v, see `ViscousDamping`).
    """

    ledger_name = "drag"
    example = "msd.Drag(0.5)"

    def __init__(self, rate: float) -> None:
        check_non_negative("drag rate", rate, "The drag rate is in 1/s.")
        self.rate = float(rate)

    def apply(self, state: StepState) -> float:
        factor = math.exp(-self.rate * state.dt)
        kinetic = equations.kinetic_energy(state.body.masses, state.v)
        state.v *= factor
        return float(kinetic * (1.0 - factor * factor))

    def __repr__(self) -> str:
        return f"Drag(rate={self.rate:g})"


class Walls(Constraint):
    """A box [lower, upper] per axis: ``"reflect"`` bounces particles back, ``"periodic"`` wraps.

    A particle found outside is put back on the wall and leaves it with the
    inward normal speed that keeps its energy: moving it back does work against
    the forces on it (lifting it against gravity, say), and that work comes out
    of its normal kinetic energy, ½ m w'² = ½ m w² - ΔU. A free bounce keeps its
    speed and the ledger books nothing. When the lift costs all the normal
    kinetic energy (a particle resting on the wall), it stays on the wall
    (w' = 0) and the ledger books the work of the wall's push at the particle's
    mean normal velocity over the step (`msdlab.engine.simulation.energy.contact_work`): zero for
    a particle at rest, a loss for one that comes to rest. So walls never put
    energy in, and a body resting on them keeps every ledger entry still.

    Periodic wrapping moves a particle across the box but not its springs, which
    then stretch across the whole box (as on the p5.js page); use it for loose
    particles, not for connected bodies.
    """

    ledger_name = "walls"
    example = "msd.Walls((-1, -1, -1), (1, 1, 1))"

    def __init__(
        self, lower: Sequence[float], upper: Sequence[float], mode: str = "reflect"
    ) -> None:
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        if self.lower.shape != self.upper.shape or np.any(self.lower >= self.upper):
            raise ValueError(f"walls need lower < upper per axis, got {lower!r} and {upper!r}")
        if mode not in ("reflect", "periodic"):
            raise ValueError(f"wall mode must be 'reflect' or 'periodic', got {mode!r}")
        self.mode = mode

    def check(self, body: Body) -> None:
        if len(self.lower) != body.dim:
            raise ValueError(f"walls have {len(self.lower)} axes but the body is {body.dim}-D")

    def apply(self, state: StepState) -> float:
        x = state.x
        outside = np.any((x < self.lower) | (x > self.upper), axis=1)
        outside = np.flatnonzero(outside & ~state.body.fixed)
        if len(outside) == 0:
            return 0.0
        if self.mode == "periodic":
            before = state.energy_of(outside)
            x[outside] = self.lower + np.mod(x[outside] - self.lower, self.upper - self.lower)
            return before - state.energy_of(outside)
        return sum(self._bounce(state, np.array([p])) for p in outside)

    def _bounce(self, state: StepState, particle: np.ndarray) -> float:
        """Put one particle back on the wall with the normal speed that keeps its energy;
        return the energy removed (J)."""
        x, v = state.x, state.v
        before = state.energy_of(particle)
        low, high = x[particle] < self.lower, x[particle] > self.upper
        hit = low | high
        incoming = np.where(hit, v[particle], 0.0)
        x[particle] = np.clip(x[particle], self.lower, self.upper)
        v[particle] = np.where(hit, 0.0, v[particle])
        spare = before - state.energy_of(particle)
        normal_kinetic = equations.kinetic_energy(state.body.masses[particle], incoming)
        if spare > 0.0 and normal_kinetic > 0.0:  # a bounce: the energy is kept
            speed = np.abs(incoming) * math.sqrt(spare / normal_kinetic)
            v[particle] = np.where(low, speed, np.where(high, -speed, v[particle]))
            return before - state.energy_of(particle)
        # held on the wall: the work of its push at the particle's mean normal velocity
        # (one that left the wall at the start of the step counts as held from rest)
        start = state.v_old[particle]
        start = np.where(low, np.minimum(start, 0.0), np.where(high, np.maximum(start, 0.0), 0.0))
        masses = state.body.masses[particle]
        return -energy.contact_work(masses, -incoming, start, np.zeros_like(start))

    def __repr__(self) -> str:
        return f"Walls({self.lower.tolist()}, {self.upper.tolist()}, mode={self.mode!r})"


class Prescribed(Constraint):
    """Particles moved along a given path: x_p(t) = path(t) (an (M, d) array, m).

    The particles are marked fixed so no force moves them; their velocity is
    the displacement over the step / dt, so dashpots and the ledger see it.
    The energy they put in is booked (negative) under "driven".
    """

    ledger_name = "driven"

    def __init__(self, particles: Sequence[int], path: Callable[[float], np.ndarray]) -> None:
        self.particles = np.atleast_1d(np.asarray(particles, dtype=np.int64))
        self.path = path

    def check(self, body: Body) -> None:
        if np.any((self.particles < 0) | (self.particles >= len(body))):
            raise ValueError(
                f"prescribed particles {self.particles.tolist()} must be indices below {len(body)}"
            )
        body.fixed[self.particles] = True

    def apply(self, state: StepState) -> float:
        target = np.broadcast_to(
            np.asarray(self.path(state.time), dtype=float), (len(self.particles), state.body.dim)
        )
        return lead(state, self.particles, target)


class Grab(Constraint):
    """A particle held by a hand (the mouse) at a target position (m) while the simulation runs.

    While held, the particle is fixed (forces do not move it), sits on the
    target, and its velocity is the target's displacement over the step / dt,
    so dashpots and the ledger see the hand's motion: the energy it puts in is booked
    (negative) under "hand". On release it keeps that velocity: zero if the hand was
    still, so it does not fling with the spring forces it resisted while held.
    """

    ledger_name = "hand"
    example = "msd.Grab()"

    def __init__(self) -> None:
        self.particle: int | None = None
        self.target: np.ndarray | None = None
        self._body: Body | None = None
        self._was_fixed = False

    def hold(self, body: Body, particle: int, target: Sequence[float] | None = None) -> None:
        """Take ``particle`` of ``body`` in hand at ``target`` (default: where it is)."""
        self.release()
        if not 0 <= particle < len(body):
            raise ValueError(f"particle {particle} does not exist: the body has {len(body)}")
        self._body, self.particle = body, int(particle)
        self._was_fixed = bool(body.fixed[particle])
        body.fixed[particle] = True
        self.move(body.positions[particle] if target is None else target)

    def move(self, target: Sequence[float]) -> None:
        """Move the hand to ``target`` (m); the particle follows at the next step."""
        self.target = np.array(target, dtype=float)

    def release(self) -> None:
        """Let go: the particle is free again (or stays fixed if it was pinned before)."""
        if self._body is not None and self.particle is not None:
            self._body.fixed[self.particle] = self._was_fixed
        self._body, self.particle, self.target = None, None, None

    def apply(self, state: StepState) -> float:
        if self.particle is None or self.target is None:
            return 0.0
        return lead(state, np.array([self.particle]), self.target)
