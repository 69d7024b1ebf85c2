"""External forces: each adds its force on every particle to a (N, d) array."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence

import numpy as np
import scipy.sparse as sp

from .body import Body
from .errors import check_non_negative, shown


class Force(ABC):
    """A force field acting on the particles of a body.

    `add_to` adds the force and returns the power it takes out (booked in the energy
    ledger under ``ledger_name``; 0 for a conservative force): whether and how it
    dissipates, from the pass that computed it. Conservative forces also give their
    potential energy, and forces that depend on x or v may give their Jacobians (for
    `ImplicitEuler`).
    """

    ledger_name = "other"
    example = ""  # how to create one, for error messages: "msd.Gravity((0, -9.81, 0))"

    def check(self, body: Body) -> None:
        """Raise ValueError if this force cannot act on ``body`` (e.g. wrong dimension)."""

    @abstractmethod
    def add_to(self, body: Body, x: np.ndarray, v: np.ndarray, out: np.ndarray) -> float:
        """Add this force on each particle (N, d), in N, to ``out``; return the power (W) it
        takes out of the body at (x, v), 0 for a conservative force."""

    def potential_energy(
        self, body: Body, x: np.ndarray, particles: np.ndarray | None = None
    ) -> float:
        """Potential energy (J) of this force, or of the terms involving ``particles``."""
        return 0.0

    def uniform_acceleration(self, body: Body) -> np.ndarray | None:
        """The acceleration g (d,) in m/s² if this force is m·g on every particle, else None.

        `Dynamics.advance` then adds g to F/m in the integrator's loop instead of
        adding m·g to the forces in a pass of its own.
        """
        return None

    def jacobians(
        self, body: Body, x: np.ndarray, v: np.ndarray
    ) -> tuple[sp.spmatrix | None, sp.spmatrix | None]:
        """∂F/∂x and ∂F/∂v (N·d square, sparse), None where zero or left explicit."""
        return None, None


class Gravity(Force):
    """Uniform gravity: F = m g on every particle; g in m/s², e.g. (0, -9.81, 0)."""

    example = "msd.Gravity((0, -9.81, 0))"

    def __init__(self, g: Sequence[float] = (0.0, -9.81, 0.0)) -> None:
        self.g = np.asarray(g, dtype=float)
        if self.g.ndim != 1 or len(self.g) not in (2, 3) or not np.all(np.isfinite(self.g)):
            raise ValueError(f"gravity must be a finite 2- or 3-vector in m/s², got {shown(g)}")

    def check(self, body: Body) -> None:
        if len(self.g) != body.dim:
            raise ValueError(
                f"Gravity g has {len(self.g)} components but the body is {body.dim}-D; "
                f"give {body.dim} components"
            )

    def add_to(self, body: Body, x: np.ndarray, v: np.ndarray, out: np.ndarray) -> float:
        for axis, g in enumerate(self.g):  # per axis: much faster than m[:, None] * g
            if g != 0.0:
                out[:, axis] += g * body.masses
        return 0.0

    def uniform_acceleration(self, body: Body) -> np.ndarray:
        return self.g

    def potential_energy(
        self, body: Body, x: np.ndarray, particles: np.ndarray | None = None
    ) -> float:
        """-Σ m g·x (J), zero at the origin."""
        pick = slice(None) if particles is None else particles
        return float(-np.sum(body.masses[pick] * (x[pick] @ self.g)))

    def __repr__(self) -> str:
        return f"Gravity({self.g.tolist()})"


class ViscousDamping(Force):
    """Linear drag F = -c v on every particle, c in N·s/m (the cloth seed's λ).

    Under explicit integrators it is stable only for c·dt/m < 2; `Drag` is stable at any dt.
    """

    ledger_name = "viscous"
    example = "msd.ViscousDamping(0.1)"

    def __init__(self, coefficient: float) -> None:
        self.coefficient = float(check_non_negative("viscous damping coefficient", coefficient))

    def add_to(self, body: Body, x: np.ndarray, v: np.ndarray, out: np.ndarray) -> float:
        """Add -c v to ``out``; return the power c Σ |v|² (W) over the free particles."""
        out -= self.coefficient * v
        free = ~body.fixed
        return float(self.coefficient * np.einsum("ij,ij->", v[free], v[free]))

    def jacobians(self, body: Body, x: np.ndarray, v: np.ndarray) -> tuple[None, sp.spmatrix]:
        return None, -self.coefficient * sp.identity(x.size, format="csr")

    def __repr__(self) -> str:
        return f"ViscousDamping({self.coefficient:g})"
