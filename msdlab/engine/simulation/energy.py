"""Energy, momentum and angular momentum of a body, and the energy ledger of a run."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import equations
from ..backends import numpy as numpy_backend
from ..equations import contact_work, damping_work
from ..model.body import Body

__all__ = [
    "EnergyLedger",
    "angular_momentum",
    "contact_work",
    "damping_work",
    "elastic_energy",
    "gravitational_energy",
    "kinetic_energy",
    "kinetic_energy_removed",
    "momentum",
]


def kinetic_energy(body: Body, v: np.ndarray | None = None) -> float:
    """½ Σ m |v|² (J); ``v`` defaults to the body's velocities."""
    return equations.kinetic_energy(body.masses, body.velocities if v is None else v)


def elastic_energy(body: Body, x: np.ndarray | None = None) -> float:
    """Σ ½ k (|x_a - x_b| - l)² over all springs (J)."""
    return numpy_backend.elastic_energy(body, body.positions if x is None else x)


def gravitational_energy(body: Body, g: Sequence[float], x: np.ndarray | None = None) -> float:
    """-Σ m g·x (J), zero at the origin; g in m/s²."""
    x = body.positions if x is None else x
    return float(-np.sum(body.masses * (x @ np.asarray(g, dtype=float))))


def momentum(body: Body, v: np.ndarray | None = None) -> np.ndarray:
    """Σ m v (kg·m/s)."""
    v = body.velocities if v is None else v
    return body.masses @ v


def angular_momentum(
    body: Body,
    x: np.ndarray | None = None,
    v: np.ndarray | None = None,
    about: Sequence[float] | None = None,
) -> np.ndarray | float:
    """Σ m (x - about) × v (kg·m²/s) about a point (default: the origin).

    A 3-vector in 3-D, a number (the z component) in 2-D.
    """
    x = body.positions if x is None else x
    v = body.velocities if v is None else v
    r = x - (0.0 if about is None else np.asarray(about, dtype=float))
    if body.dim == 2:
        return float(np.sum(body.masses * (r[:, 0] * v[:, 1] - r[:, 1] * v[:, 0])))
    return body.masses @ np.cross(r, v)


def kinetic_energy_removed(masses: np.ndarray, v: np.ndarray, factor: float) -> float:
    """Kinetic energy (J) taken out when velocities ``v`` are scaled by ``factor``:
    (1 - factor²)·½ Σ m v²."""
    return float((1.0 - factor * factor) * equations.kinetic_energy(masses, v))


@dataclass
class EnergyLedger:
    """Energy bookkeeping of a run, one row per recorded frame (all in J).

    ``kinetic``, ``elastic`` (springs) and ``potential`` (external forces:
    gravity, contact) are the energy in the body; ``dissipated[source]`` is the
    energy taken out so far by each mechanism (dashpot, drag, ground, damping of
    the integrator, ...; negative when a driver put energy in). What is left,
    ``drift = total + Σ dissipated - total[0]``, is the integrator's own error.
    """

    steps: list[int] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    kinetic: list[float] = field(default_factory=list)
    elastic: list[float] = field(default_factory=list)
    potential: list[float] = field(default_factory=list)
    dissipated: dict[str, list[float]] = field(default_factory=dict)

    def record(
        self,
        step: int,
        time: float,
        kinetic: float,
        elastic: float,
        potential: float,
        dissipated: dict[str, float],
    ) -> None:
        """Append one frame."""
        frames = len(self.steps)
        for name, value in dissipated.items():
            self.dissipated.setdefault(name, [0.0] * frames).append(value)
        for values in self.dissipated.values():
            if len(values) == frames:
                values.append(0.0)
        self.steps.append(step)
        self.times.append(time)
        self.kinetic.append(kinetic)
        self.elastic.append(elastic)
        self.potential.append(potential)

    @property
    def total(self) -> np.ndarray:
        """Kinetic + elastic + potential energy per frame."""
        return np.add(np.add(self.kinetic, self.elastic), self.potential)

    @property
    def total_dissipated(self) -> np.ndarray:
        """Energy taken out by all mechanisms so far, per frame."""
        return (
            np.sum([np.asarray(v) for v in self.dissipated.values()], axis=0)
            if self.dissipated
            else np.zeros(len(self.steps))
        )

    @property
    def drift(self) -> np.ndarray:
        """Energy the integrator created (> 0) or lost (< 0) on its own, per frame."""
        total = self.total
        return total + self.total_dissipated - (total[0] if len(total) else 0.0)

    def relative_drift(self) -> float:
        """Largest |drift| over the run relative to the energy scale of the run."""
        total = self.total
        scale = max(
            np.max(np.abs(total)), np.max(np.abs(self.kinetic)), np.max(self.elastic), 1e-300
        )
        return float(np.max(np.abs(self.drift)) / scale)

    def table(self, rows: int = 8) -> str:
        """The ledger as a text table of about ``rows`` evenly spaced frames."""
        names = sorted(self.dissipated)
        header = ["time", "kinetic", "elastic", "potential", "total", *names, "drift"]
        picks = np.unique(
            np.linspace(0, len(self.steps) - 1, min(rows, len(self.steps))).astype(int)
        )
        total, drift = self.total, self.drift
        lines = [" ".join(f"{h:>12}" for h in header)]
        for i in picks:
            values = [self.times[i], self.kinetic[i], self.elastic[i], self.potential[i], total[i]]
            values += [self.dissipated[n][i] for n in names] + [drift[i]]
            lines.append(" ".join(f"{value:>12.5g}" for value in values))
        return "\n".join(lines)

    def as_arrays(self) -> dict[str, np.ndarray]:
        """Every column as an array, dissipation columns named ``dissipated_<source>``."""
        columns = {
            "step": np.asarray(self.steps),
            "time": np.asarray(self.times),
            "kinetic": np.asarray(self.kinetic),
            "elastic": np.asarray(self.elastic),
            "potential": np.asarray(self.potential),
            "total": self.total,
        }
        columns.update({f"dissipated_{k}": np.asarray(v) for k, v in self.dissipated.items()})
        columns["drift"] = self.drift
        return columns
