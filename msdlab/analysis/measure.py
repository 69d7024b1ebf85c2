"""Experiments on a simulation: the real blow-up dt, and the order of convergence."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np

from ..engine.backends import numpy as numpy_backend
from ..engine.integrators import Integrator
from ..engine.model.body import Body
from ..engine.model.constraint import Constraint
from ..engine.model.errors import SimulationDiverged
from ..engine.model.forces import Force
from ..engine.model.springs import EdgeSprings
from ..engine.simulation.simulation import Simulation
from ..engine.simulation.stability import max_stable_dt


def bisect_blowup(
    is_stable: Callable[[float], bool], low: float, high: float, rtol: float = 1e-3
) -> float:
    """Largest dt in [low, high] for which ``is_stable(dt)`` holds, by bisection (log scale).

    ``is_stable(low)`` must be true and ``is_stable(high)`` false.
    """
    if not is_stable(low):
        raise ValueError(f"the simulation is already unstable at the lower bound dt = {low:g} s")
    if is_stable(high):
        raise ValueError(f"the simulation is still stable at the upper bound dt = {high:g} s")
    while high > low * (1.0 + rtol):
        middle = math.sqrt(low * high)
        if is_stable(middle):
            low = middle
        else:
            high = middle
    return low


def measure_blowup_dt(
    body: Body,
    integrator: Integrator,
    forces: Sequence[Force | Constraint] = (),
    *,
    steps: int = 1000,
    perturbation: float = 1e-3,
    seed: int = 0,
    low: float | None = None,
    high: float | None = None,
    rtol: float = 1e-3,
) -> float:
    """Measured largest stable dt (s) of ``integrator`` on ``body``.

    Each trial perturbs the particles randomly by ``perturbation`` × the shortest
    rest length, runs ``steps`` steps, and calls the run unstable if it diverges
    or the largest spring strain |l/l₀ - 1| ever grows 100-fold (checked every
    step: a damped body may blow up, fold over and settle again). Bounds
    default to 1/5 and 3 times `max_stable_dt`.
    """
    predicted = max_stable_dt(body, integrator, [f for f in forces if isinstance(f, Force)])
    if low is None or high is None:
        if not 0 < predicted < math.inf:
            raise ValueError(f"give low= and high= bounds: the predicted limit is {predicted}")
        low, high = predicted / 5 if low is None else low, predicted * 3 if high is None else high
    rng = np.random.default_rng(seed)
    kick = (
        perturbation
        * float(np.min(body.spring_set.rest_lengths))
        * rng.standard_normal(body.positions.shape)
    )
    kick[body.fixed] = 0.0
    is_stable = partial(_stays_stable, body, integrator, forces, kick, steps)
    return bisect_blowup(is_stable, low, high, rtol)


def _strain(edges: EdgeSprings, positions: np.ndarray) -> float:
    """The largest strain |l/l₀ - 1| of the springs ``edges`` at ``positions`` (N, d) in m."""
    _, length = numpy_backend.vectors(edges, positions)
    return float(np.max(np.abs(length / edges.rest_lengths - 1.0)))


def _stays_stable(
    body: Body,
    integrator: Integrator,
    forces: Sequence[Force | Constraint],
    kick: np.ndarray,
    steps: int,
    dt: float,
) -> bool:
    """Whether a copy of ``body`` moved by ``kick`` (m) and at rest runs ``steps`` steps of
    ``dt`` (s) without diverging or its largest strain growing 100-fold."""
    trial = body.copy()
    trial.positions = trial.positions + kick
    trial.velocities = np.zeros_like(trial.velocities)
    edges = trial.edges()  # a lattice laid out once for the whole run
    limit = 100.0 * _strain(edges, trial.positions)

    def watch(sim: Simulation) -> None:
        if _strain(edges, sim.body.positions) > limit:
            raise SimulationDiverged(sim.step_count, sim.time, "strain grew 100-fold")

    try:
        Simulation(trial, integrator, dt, forces).run(steps, record_every=steps, callback=watch)
    except SimulationDiverged:
        return False
    return True


@dataclass
class Convergence:
    """Errors of a computation at several dt and the fitted order p (error ∝ dtᵖ)."""

    dts: np.ndarray
    errors: np.ndarray
    order: float

    def __str__(self) -> str:
        rows = [f"{'dt (s)':>12} {'error':>12}"]
        rows += [f"{dt:12.4g} {error:12.4g}" for dt, error in zip(self.dts, self.errors)]
        return "\n".join([*rows, f"observed order: {self.order:.2f}"])


def convergence_order(
    solve: Callable[[float], np.ndarray],
    dts: Sequence[float],
    reference: np.ndarray | None = None,
) -> Convergence:
    """Fit the order of convergence of ``solve(dt)`` (e.g. final positions) to ``reference``.

    ``reference`` is an analytic answer; without it, ``solve`` at dt/32 of the
    smallest dt stands in (a fine-step reference).
    """
    dts = np.asarray(sorted(dts, reverse=True), dtype=float)
    if len(dts) < 2 or np.any(dts <= 0):
        raise ValueError("give at least two positive time steps")
    reference = solve(dts[-1] / 32) if reference is None else np.asarray(reference)
    errors = np.array([np.max(np.abs(np.asarray(solve(dt)) - reference)) for dt in dts])
    order = float(np.polyfit(np.log(dts), np.log(errors), 1)[0])
    return Convergence(dts, errors, order)
