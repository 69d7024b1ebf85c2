"""The live view's instruments, as in PhET's Masses and Springs toolbox, measured in Python
(the page only draws them): a stopwatch on the simulated time, a ruler between two
particles, a trace of one particle's position and velocity against time with its period,
the natural-length and equilibrium lines of a particle hung on a spring, the velocity and
force on a particle (arrows), and gravity presets.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .. import Body, Gravity, Simulation

TOOLS = ("stopwatch", "ruler", "trace", "lines", "arrows")  # the page's toggles, in order
GRAVITY = {"Earth": 9.81, "Moon": 1.62, "Jupiter": 24.79, "zero": 0.0}  # |g| in m/s²
TRACE_STEPS = 20_000  # steps a trace keeps (the latest)
TRACE_SHOWN = 240  # points of the trace sent to the page


class Stopwatch:
    """A stopwatch on the simulated time ``clock()`` (s, or the scene's time unit):
    `start`, `stop`, `reset`; `reading` is the time counted while it ran."""

    def __init__(self, clock: Callable[[], float]) -> None:
        self.clock = clock
        self.running = False
        self._counted = 0.0  # before the last start
        self._since = 0.0  # the clock at the last start

    def start(self) -> None:
        if not self.running:
            self.running, self._since = True, self.clock()

    def stop(self) -> None:
        if self.running:
            self._counted, self.running = self.reading, False

    def reset(self) -> None:
        """Back to zero (still running if it ran, from now)."""
        self._counted, self._since = 0.0, self.clock()

    @property
    def reading(self) -> float:
        return self._counted + (self.clock() - self._since if self.running else 0.0)


class Trace:
    """Particle ``particle``'s position and velocity along ``axis`` against time, at every
    step (the latest `TRACE_STEPS`), and the period of its oscillation."""

    def __init__(self, particle: int, axis: int) -> None:
        self.particle, self.axis = particle, axis
        self._data = np.empty((TRACE_STEPS, 3))  # time, position, velocity (a ring)
        self._count = 0

    def record(self, sim: Simulation) -> None:
        """Add the particle's state now (after a step)."""
        body = sim.body
        row = (sim.time, body.positions[self.particle, self.axis])
        self._data[self._count % TRACE_STEPS] = (*row, body.velocities[self.particle, self.axis])
        self._count += 1

    @property
    def points(self) -> np.ndarray:
        """(time, position, velocity) rows, oldest first."""
        if self._count <= TRACE_STEPS:
            return self._data[: self._count]
        return np.roll(self._data, -(self._count % TRACE_STEPS), axis=0)

    def period(self) -> float | None:
        """The mean time between the upward crossings of the middle of the traced range,
        interpolated between steps (for x = A cos(ωt) + c, 2π/ω); None before two."""
        t, x = self.points[:, 0], self.points[:, 1]
        if len(x) < 3:
            return None
        level = 0.5 * (x.min() + x.max())
        up = np.flatnonzero((x[:-1] < level) & (x[1:] >= level))
        if len(up) < 2 or x.max() - x.min() <= 1e-12 * max(1.0, abs(level)):
            return None
        crossings = t[up] + (level - x[up]) / (x[up + 1] - x[up]) * (t[up + 1] - t[up])
        return float((crossings[-1] - crossings[0]) / (len(crossings) - 1))

    def shown(self) -> list[list[float]]:
        """At most `TRACE_SHOWN` evenly spaced points, the last included, for the page."""
        points = self.points
        every = max(1, -(-len(points) // TRACE_SHOWN))
        return points[::-1][::every][::-1].tolist()


def gravity_of(sim: Simulation) -> Gravity | None:
    return next((f for f in sim.forces if isinstance(f, Gravity)), None)


def hung_from(body: Body, particle: int) -> tuple[int, int] | None:
    """(spring, anchor) when ``particle`` hangs by its only spring from a pinned particle
    (the anchor), held in hand or not; else None."""
    springs = body.springs_touching(np.array([particle]))
    if len(springs) != 1:
        return None
    spring = body.springs[int(springs[0])]
    anchor = spring.a + spring.b - particle
    return (spring.index, anchor) if body.fixed[anchor] else None


def hanging_lines(sim: Simulation, particle: int) -> dict[str, list[float]] | None:
    """Where ``particle``, hung by one spring (rest length L, stiffness k) from a pinned
    anchor, is at the spring's natural length (anchor + L ĝ) and at equilibrium
    (anchor + (L + m|g|/k) ĝ, ĝ along gravity, or where the spring now points without
    gravity). None for a particle not hung so."""
    body, hung = sim.body, hung_from(sim.body, particle)
    if hung is None:
        return None
    spring, anchor = hung
    gravity = gravity_of(sim)
    g = gravity.g if gravity is not None else np.zeros(body.dim)
    pull = body.positions[particle] - body.positions[anchor]
    down = g if np.any(g) else pull
    down = down / max(float(np.linalg.norm(down)), 1e-300)
    rest, k = body.springs[spring].rest_length, body.springs[spring].stiffness
    stretch = float(body.masses[particle] * np.linalg.norm(g) / k)
    at = body.positions[anchor]
    return {
        "natural": (at + rest * down).tolist(),
        "equilibrium": (at + (rest + stretch) * down).tolist(),
    }


def arrows(sim: Simulation, particle: int) -> dict[str, list[float]]:
    """Particle ``particle``'s velocity and the net force on it, m a (the engine's
    acceleration of the state now: springs, gravity and the scene's forces)."""
    x, v = sim.body.positions, sim.body.velocities
    acceleration = sim.dynamics.acceleration(x, v)[particle]
    force = sim.body.masses[particle] * acceleration
    return {"velocity": v[particle].tolist(), "force": force.tolist()}


def distance(sim: Simulation, ends: tuple[int, int]) -> float:
    """The distance between two particles (length units)."""
    a, b = ends
    return float(np.linalg.norm(sim.body.positions[a] - sim.body.positions[b]))


def lowest_free(sim: Simulation, up: int) -> int:
    """The free particle lowest along axis ``up`` (a hung mass; the end of a rope)."""
    body = sim.body
    heights = np.where(body.fixed, np.inf, body.positions[:, up])
    return int(np.argmin(heights)) if not np.all(body.fixed) else 0


@dataclass
class GravityPresets:
    """|g| of Earth, Moon, Jupiter and zero in the scene's units: ``earth`` is Earth's |g|
    there (9.81 in SI), the others scaled by their ratio to Earth's."""

    earth: float

    def values(self) -> dict[str, float]:
        return {name: self.earth * g / GRAVITY["Earth"] for name, g in GRAVITY.items()}

    def value(self, name: str) -> float:
        values = self.values()
        if name not in values:
            raise ValueError(f"no gravity preset {name!r}: choose one of {', '.join(values)}")
        return values[name]
