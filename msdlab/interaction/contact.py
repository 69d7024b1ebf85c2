"""Contact with a ball: a penalty force between one particle (the ball) and the others."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..engine.model.body import Body
from ..engine.model.errors import check_positive
from ..engine.model.forces import Force


class SphereContact(Force):
    """A ball that pushes particles out of it with a penalty spring.

    The ball is particle ``center`` of the body (so it has a mass, moves, and
    feels the reaction): every other particle p inside the ball, at depth
    δ = radius - |x_p - x_c| > 0, gets f = stiffness·δ·n (n from the centre to p)
    and the ball gets -f, so contact forces are equal and opposite.
    A fixed ``center`` makes a still obstacle.
    """

    def __init__(
        self, center: int, radius: float, stiffness: float, particles: Sequence[int] | None = None
    ) -> None:
        self.center = int(center)
        self.radius = check_positive("sphere radius", radius, "The ball radius is in m.")
        self.stiffness = check_positive("contact stiffness", stiffness, "It is in N/m.")
        self.particles = None if particles is None else np.asarray(particles, dtype=np.int64)

    def check(self, body: Body) -> None:
        if not 0 <= self.center < len(body):
            raise ValueError(
                f"sphere centre particle {self.center} does not exist: the body has "
                f"{len(body)} particles"
            )

    def _others(self, body: Body) -> np.ndarray:
        if self.particles is None:
            others = np.arange(len(body))
            return others[others != self.center]
        return self.particles[self.particles != self.center]

    def _depths(self, body: Body, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        others = self._others(body)
        d = x[others] - x[self.center]
        distance = np.sqrt(np.einsum("ij,ij->i", d, d))
        inside = distance < self.radius
        return others[inside], d[inside], distance[inside]

    def add_to(self, body: Body, x: np.ndarray, v: np.ndarray, out: np.ndarray) -> float:
        touched, d, distance = self._depths(body, x)
        if len(touched) == 0:
            return 0.0
        depth = self.radius - distance
        direction = d / np.where(distance > 0, distance, np.inf)[:, None]
        f = (self.stiffness * depth)[:, None] * direction
        np.add.at(out, touched, f)
        out[self.center] -= f.sum(axis=0)
        return 0.0  # a penalty spring: conservative

    def potential_energy(
        self, body: Body, x: np.ndarray, particles: np.ndarray | None = None
    ) -> float:
        """Σ ½ stiffness δ² over particles inside the ball (J)."""
        touched, _, distance = self._depths(body, x)
        energy = 0.5 * self.stiffness * (self.radius - distance) ** 2
        if particles is not None and self.center not in particles:
            energy = energy[np.isin(touched, particles)]
        return float(energy.sum())

    def __repr__(self) -> str:
        return (
            f"SphereContact(center={self.center}, radius={self.radius:g}, "
            f"stiffness={self.stiffness:g})"
        )
