"""The p5.js springs page's per-frame model, as an integrator (seed ``004``).

The page's ``draw()`` does, for unit masses, in this order: for each particle,
add the external forces (gravity) to v, then ``update()``: v *= damping, cap
the speed at ``max_speed``, apply the wall rule to the position *before* the
move, x += v; only then, for each spring, add its force at the new positions
to v. So the springs act at the end of a frame and first move the particles in
the next one: in the very first frame only gravity acts. With dt in frames::

    u = cap(damping·(v + a_ext(x) dt)),  walls(x, u),  x' = x + u dt,  v' = u + a_spring(x') dt

The state (x, v) between frames is the page's own (px, py, vx, vy) after
``draw()`` (y up here). Springs push only when their ends are more than
``min_length`` (1 px) apart. Walls follow the page's rule: hard walls test the
position before the move and turn the velocity inward without moving the
particle back (it may end up to one frame's move past the wall); periodic walls
wrap the position before the move. The speed cap hides instability (a stiff
spring oscillates at the cap instead of blowing up): the physical model has no
cap, no dead zone, and walls that put particles back on the wall.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import Dynamics, Integrator
from ..engine import equations
from ..engine.backends import numpy as numpy_backend
from ..engine.backends.contract import SpringKernel
from ..engine.integrators import State

WALL_RULES = ("hard", "periodic")


class FrameEuler(Integrator):
    """The page's ``draw()``: velocity ``damping`` per frame (in (0, 1]), speed cap,
    1 px dead zone, and optionally its walls on the box ``lower``-``upper`` (px)."""

    def __init__(
        self,
        damping: float = 0.96,
        max_speed: float | None = 10.0,
        min_length: float = 1.0,
        walls: str | None = None,
        lower: Sequence[float] = (0.0, 0.0),
        upper: Sequence[float] = (600.0, 400.0),
    ) -> None:
        damping = float(damping)
        if not 0.0 < damping <= 1.0:
            raise ValueError(
                f"the per-frame damping factor must be in (0, 1], got {damping}: 1 keeps all "
                "the velocity, 0.96 (the page's) loses 4 % per frame; above 1 adds energy"
            )
        if max_speed is not None and not max_speed > 0:
            raise ValueError(f"max_speed must be > 0 (px per frame) or None, got {max_speed}")
        if walls is not None and walls not in WALL_RULES:
            raise ValueError(f"the page's walls are 'hard' or 'periodic' (or None), got {walls!r}")
        self.damping = damping
        self.max_speed = max_speed
        self.min_length = float(min_length)
        self.walls = walls
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        body = dynamics.body
        masses, free = body.masses[:, None], ~body.fixed[:, None]
        external = np.zeros_like(x)
        for force in dynamics.forces:
            force.add_to(body, x, v, external)
        u = self.damping * (v + dt * equations.acceleration(external, masses, free))
        if self.max_speed is not None:
            speed = np.sqrt(np.einsum("ij,ij->i", u, u))[:, None]
            capped = u * (self.max_speed / np.maximum(speed, self.max_speed))
            u = np.where(speed > self.max_speed, capped, u)
        start = x
        if self.walls == "hard":
            u = np.where(x >= self.upper, -np.abs(u), np.where(x <= self.lower, np.abs(u), u))
        elif self.walls == "periodic":
            span = self.upper - self.lower
            start = np.where(x > self.upper, x - span, x)
            start = np.where(start < self.lower, start + span, start)
            start = np.where(body.fixed[:, None], x, start)
        x_new = start + dt * u
        _, length = numpy_backend.spring_vectors(body, x_new)
        pushing = np.flatnonzero(length > self.min_length)
        springs, _ = numpy_backend.spring_forces(body, x_new, u, springs=pushing)
        return x_new, u + dt * equations.acceleration(springs, masses, free)

    def dissipated_energy(
        self,
        v: np.ndarray,
        masses: np.ndarray,
        v_new: np.ndarray | None = None,
        *,
        kernel: SpringKernel | None = None,
    ) -> float:
        """Kinetic energy the per-frame factor removes: (1 - damping²)·½ Σ m v²."""
        kinetic = 0.5 * np.sum(masses * np.einsum("ij,ij->i", v, v))
        return float((1.0 - self.damping**2) * kinetic)

    def __repr__(self) -> str:
        walls = "" if self.walls is None else f", walls={self.walls!r}"
        return f"FrameEuler(damping={self.damping:g}, max_speed={self.max_speed}{walls})"
