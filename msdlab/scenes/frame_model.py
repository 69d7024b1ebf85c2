"""The p5.js springs page's per-frame model, as an integrator (seed ``004``).

Each animation frame the page does, for unit masses: v += F/m (gravity and
springs), v *= damping, cap the speed at ``max_speed``, x += v. With dt in
frames that is symplectic Euler with a velocity factor per frame::

    v(t+dt) = cap(damping·(v(t) + a(x(t)) dt)),    x(t+dt) = x(t) + v(t+dt) dt

Springs push only when their ends are more than ``min_length`` (1 px) apart.
The speed cap hides instability (a stiff spring oscillates at the cap instead
of blowing up): compare with the physical model, which has no cap.
"""

from __future__ import annotations

import numpy as np

from .. import kernels
from ..dynamics import Dynamics
from ..integrators import Integrator, State


class FrameEuler(Integrator):
    """The page's update: velocity ``damping`` per frame (in (0, 1]), speed cap, 1 px dead zone."""

    def __init__(
        self, damping: float = 0.96, max_speed: float | None = 10.0, min_length: float = 1.0
    ) -> None:
        damping = float(damping)
        if not 0.0 < damping <= 1.0:
            raise ValueError(
                f"the per-frame damping factor must be in (0, 1], got {damping}: 1 keeps all "
                "the velocity, 0.96 (the page's) loses 4 % per frame; above 1 adds energy"
            )
        if max_speed is not None and not max_speed > 0:
            raise ValueError(f"max_speed must be > 0 (px per frame) or None, got {max_speed}")
        self.damping = damping
        self.max_speed = max_speed
        self.min_length = float(min_length)

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics) -> State:
        a = dynamics.acceleration(x, v) - self._dead_zone_acceleration(x, v, dynamics)
        v_new = self.damping * (v + dt * a)
        if self.max_speed is not None:
            speed = np.linalg.norm(v_new, axis=1, keepdims=True)
            v_new *= np.minimum(1.0, self.max_speed / np.maximum(speed, 1e-300))
        return x + dt * v_new, v_new

    def _dead_zone_acceleration(
        self, x: np.ndarray, v: np.ndarray, dynamics: Dynamics
    ) -> np.ndarray:
        """Acceleration from the springs shorter than ``min_length`` (the page ignores them)."""
        body = dynamics.body
        _, length = kernels.spring_vectors(body, x)
        short = np.flatnonzero(length <= self.min_length)
        if len(short) == 0:
            return 0.0 * x
        force, _ = kernels.spring_forces(body, x, v, springs=short)
        return force * np.where(body.fixed, 0.0, 1.0 / body.masses)[:, None]

    def dissipated_energy(
        self, v: np.ndarray, masses: np.ndarray, v_new: np.ndarray | None = None
    ) -> float:
        """Kinetic energy the per-frame factor removes: (1 - damping²)·½ Σ m v²."""
        kinetic = 0.5 * np.sum(masses * np.einsum("ij,ij->i", v, v))
        return float((1.0 - self.damping**2) * kinetic)

    def __repr__(self) -> str:
        return f"FrameEuler(damping={self.damping:g}, max_speed={self.max_speed})"
