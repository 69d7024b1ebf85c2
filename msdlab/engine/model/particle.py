"""Particle: one point mass of a body."""

from __future__ import annotations

import numpy as np

from .bound import Bound, Field
from .errors import as_vectors, check_finite_array, check_non_negative, check_positive, shown


def _coordinates(value: object) -> np.ndarray:
    vector = np.array(value, dtype=float)
    if vector.ndim != 1 or len(vector) not in (2, 3):
        raise ValueError(
            f"a particle position or velocity needs 2 or 3 coordinates, got {shown(value)}"
        )
    check_finite_array("particle position and velocity", vector[None])
    return vector


MASS_HINT = "Give every particle a mass > 0 (kg); to pin a particle use fixed=True."


def _mass(value: float) -> float:
    return check_positive("mass", value, MASS_HINT)


def checked_masses(masses: object, count: int) -> np.ndarray:
    """``masses`` (kg), one or one per particle, checked > 0, as ``count`` floats."""
    array = check_non_negative("mass", masses, MASS_HINT, zero=False)
    if array.ndim and array.shape != (count,):
        raise ValueError(f"mass needs one value or one per particle ({count}), got {array.shape}")
    return np.broadcast_to(array, (count,)).copy()


def particle_arrays(
    dim: int | None, positions: object, velocities: object, masses: object, fixed: object
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """New particles' positions (N, d), velocities (zero if fixed or None), masses (N,) and
    fixed mask (N,), checked for a body of ``dim`` (None: not chosen yet)."""
    positions = np.array(positions, dtype=float)
    width = positions.shape[-1] if positions.ndim == 2 else None
    if width not in (2, 3):
        raise ValueError(f"positions must have shape (N, 2) or (N, 3), got {positions.shape}")
    if dim not in (None, width):
        raise ValueError(
            f"this body is {dim}-D but the new particle has {width} coordinates; "
            "do not mix 2-D and 3-D particles in one body"
        )
    count = len(positions)
    positions = as_vectors("positions", positions, width, count)
    velocities = np.zeros(width) if velocities is None else velocities
    velocities = as_vectors("velocities", velocities, width, count)
    fixed = np.broadcast_to(np.asarray(fixed, dtype=bool), (count,)).copy()
    velocities[fixed] = 0.0
    return positions, velocities, checked_masses(masses, count), fixed


class _Pin(Field):
    """``fixed``: pinning a particle also zeroes its velocity."""

    def __set__(self, particle: Particle, value: object) -> None:
        super().__set__(particle, value)
        if value:
            particle.velocity[...] = 0.0


class Particle(Bound):
    """A point mass: position (m), velocity (m/s), mass (kg), and whether it is fixed.

    Made on its own it holds its values; added to a `Body` (or read back as
    ``body.particles[i]``) it reads and writes the body's arrays, so
    ``body.particles[3].position = (0, 1, 0)`` moves particle 3 of the body.
    A fixed particle never moves: its velocity stays zero whatever acts on it.
    """

    position = Field("positions", "Position (m), a writeable view when bound.", _coordinates, None)
    velocity = Field(
        "velocities", "Velocity (m/s), a writeable view when bound.", _coordinates, None
    )
    mass = Field("masses", "Mass (kg).", _mass)
    fixed = _Pin("fixed", "True if the particle is pinned in place.", bool, bool)

    def __init__(
        self, position: object, velocity: object = None, mass: float = 1.0, fixed: bool = False
    ) -> None:
        super().__init__()
        self.position = position
        self.velocity = np.zeros_like(self.position) if velocity is None else velocity
        if self.velocity.shape != self.position.shape:
            raise ValueError(
                f"velocity {self.velocity.tolist()} must have as many coordinates as the "
                f"position {self.position.tolist()}"
            )
        self.mass, self.fixed = mass, fixed

    @property
    def dim(self) -> int:
        """Number of coordinates (2 or 3)."""
        return len(self.position)

    def __repr__(self) -> str:
        where = f"index={self.index}, " if self.body is not None else ""
        return (
            f"Particle({where}position={self.position.tolist()}, "
            f"velocity={self.velocity.tolist()}, mass={self.mass:g}, fixed={self.fixed})"
        )
