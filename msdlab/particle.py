"""Particle: one point mass of a body."""

from __future__ import annotations

import numpy as np

from .bound import Bound
from .errors import check_finite_array, check_positive

MASS_HINT = "Give every particle a mass > 0 (kg); to pin a particle use fixed=True."


class Particle(Bound):
    """A point mass: position (m), velocity (m/s), mass (kg), and whether it is fixed.

    Made on its own it holds its values; once added to a `Body` (or read back as
    ``body.particles[i]``) it reads and writes the body's arrays, so
    ``body.particles[3].position = (0, 1, 0)`` moves particle 3 of the body.
    A fixed particle never moves: its velocity stays zero whatever acts on it.
    """

    def __init__(
        self,
        position: object,
        velocity: object = None,
        mass: float = 1.0,
        fixed: bool = False,
    ) -> None:
        position = np.array(position, dtype=float)
        if position.ndim != 1 or len(position) not in (2, 3):
            raise ValueError(
                f"a particle position needs 2 or 3 coordinates, got {position.tolist()!r}"
            )
        check_finite_array("particle position", position[None])
        velocity = np.zeros_like(position) if velocity is None else np.array(velocity, float)
        if velocity.shape != position.shape:
            raise ValueError(
                f"velocity {velocity.tolist()!r} must have as many coordinates as the "
                f"position {position.tolist()!r}"
            )
        check_finite_array("particle velocity", velocity[None])
        mass = check_positive("mass", mass, MASS_HINT)
        super().__init__(position=position, velocity=velocity, mass=mass, fixed=fixed)

    @property
    def dim(self) -> int:
        """Number of coordinates (2 or 3)."""
        return len(self.position)

    @property
    def position(self) -> np.ndarray:
        """Position (m); a writeable view into the body's ``positions`` when bound."""
        return self._own["position"] if self._body is None else self._body.positions[self._index]

    @position.setter
    def position(self, value: object) -> None:
        value = np.asarray(value, dtype=float)
        check_finite_array("particle position", value.reshape(1, -1))
        self.position[...] = value

    @property
    def velocity(self) -> np.ndarray:
        """Velocity (m/s); a writeable view into the body's ``velocities`` when bound."""
        return self._own["velocity"] if self._body is None else self._body.velocities[self._index]

    @velocity.setter
    def velocity(self, value: object) -> None:
        value = np.asarray(value, dtype=float)
        check_finite_array("particle velocity", value.reshape(1, -1))
        self.velocity[...] = value

    @property
    def mass(self) -> float:
        """Mass (kg)."""
        return self._own["mass"] if self._body is None else float(self._body.masses[self._index])

    @mass.setter
    def mass(self, value: float) -> None:
        value = check_positive("mass", value, MASS_HINT)
        if self._body is None:
            self._own["mass"] = value
        else:
            self._body.masses[self._index] = value

    @property
    def fixed(self) -> bool:
        """True if the particle is pinned in place."""
        return self._own["fixed"] if self._body is None else bool(self._body.fixed[self._index])

    @fixed.setter
    def fixed(self, value: bool) -> None:
        if self._body is None:
            self._own["fixed"] = bool(value)
        else:
            self._body.fixed[self._index] = bool(value)
        if value:
            self.velocity[...] = 0.0

    def __repr__(self) -> str:
        where = f"index={self._index}, " if self._body is not None else ""
        return (
            f"Particle({where}position={self.position.tolist()}, "
            f"velocity={self.velocity.tolist()}, mass={self.mass:g}, fixed={self.fixed})"
        )
