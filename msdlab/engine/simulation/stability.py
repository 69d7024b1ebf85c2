"""How large may dt be? Prediction from the stiffest mode, and the diagnosis of a blow-up.

A linear mass-spring system splits into modes x'' = -ω² x - γ x'. An integrator
is stable for a mode when its one-step map on (x, v) has spectral radius <= 1;
`stability_limit` finds the largest such dt by running the integrator's own
`step` on that one mode, so it works for any `Integrator`, a student's included.
`max_stable_dt` applies it to the stiffest mode of a body: the largest
eigenvalue ω² of M⁻¹K (K = -∂F/∂x of the springs). `describe_blowup` is what
`Simulation` reports when a step blows up.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..backends import numpy as numpy_backend
from ..integrators import Integrator
from ..model.body import Body
from ..model.forces import Force

SCAN_PER_DECADE = 4  # trial dts a decade of `stability_limit`'s scan (a factor 1.78 apart)
LIMIT_RTOL = 1e-8  # relative precision of `stability_limit` (the checks compare at 1e-6)


@dataclass(frozen=True)
class Mode:
    """A vibration mode: angular frequency ω (rad/s) and damping rate γ (1/s)."""

    omega: float
    gamma: float = 0.0

    @property
    def period(self) -> float:
        """2π/ω (s)."""
        return 2 * math.pi / self.omega if self.omega > 0 else math.inf


def stiffest_mode(body: Body, forces: Sequence[Force] = (), x: np.ndarray | None = None) -> Mode:
    """The highest-frequency mode of the free particles of ``body`` at positions ``x``.

    ω² is the largest eigenvalue of M⁻¹K; γ is the damping (dashpots and
    viscous forces) seen by that mode, uᵀCu / uᵀMu.
    """
    import scipy.linalg  # here: 0.3 s to import, spared where no mode is asked for (a check)
    import scipy.sparse.linalg as spla

    x = body.positions if x is None else x
    jx, jv = numpy_backend.spring_jacobians(body, x)
    for force in forces:
        fx, fv = force.jacobians(body, x, body.velocities)
        jx = jx if fx is None else jx + fx
        jv = jv if fv is None else jv + fv
    free = np.repeat(~body.fixed, body.dim)
    if not free.any() or body.n_springs == 0:
        return Mode(0.0)
    scale = 1.0 / np.sqrt(np.repeat(body.masses, body.dim)[free])
    stiffness = sp.diags(scale) @ (-jx.tocsr()[free][:, free]) @ sp.diags(scale)
    damping = sp.diags(scale) @ (-jv.tocsr()[free][:, free]) @ sp.diags(scale)
    if stiffness.shape[0] <= 400:
        values, vectors = scipy.linalg.eigh(stiffness.toarray())
        value, vector = values[-1], vectors[:, -1]
    else:
        values, vectors = spla.eigsh(stiffness, k=1, which="LA", tol=1e-10)
        value, vector = values[0], vectors[:, 0]
    gamma = float(vector @ (damping @ vector)) / float(vector @ vector)
    return Mode(math.sqrt(max(value, 0.0)), max(gamma, 0.0))


class _OneMode:
    """The dynamics of one mode, x'' = -ω² x - γ x', in the form integrators expect.

    Each row of x is a copy of the mode of its own (unit mass, no coupling).
    """

    def __init__(self, mode: Mode, copies: int) -> None:
        self.mode = mode
        self.masses = np.ones(copies)
        self.free = np.ones(copies, dtype=bool)

    def force(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        return -(self.mode.omega**2) * x - self.mode.gamma * v

    acceleration = force  # unit mass

    def advance(
        self, update: Callable, x: np.ndarray, v: np.ndarray, dt: float, *coefficients: float
    ) -> tuple[np.ndarray, np.ndarray]:
        return update(x, v, self.acceleration(x, v), dt, *coefficients)

    def implicit_matrix(
        self, x: np.ndarray, v: np.ndarray, h_v: float, h_x: float
    ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        identity = sp.identity(x.size, format="csr")
        jx = -(self.mode.omega**2) * identity
        return (1.0 + h_v * self.mode.gamma) * identity - h_x * jx, jx


def spectral_radius(integrator: Integrator, mode: Mode, dt: float) -> float:
    """Spectral radius of the integrator's one-step map on (x, v) for ``mode``.

    One step of two copies of the mode, started at (x, v) = (1, 0) and (0, 1),
    gives the map's two columns.
    """
    start_x, start_v = np.array([[1.0], [0.0]]), np.array([[0.0], [1.0]])
    x, v = integrator.step(start_x, start_v, dt, _OneMode(mode, 2))  # type: ignore[arg-type]
    step_map = np.array([np.asarray(x, dtype=float).ravel(), np.asarray(v, dtype=float).ravel()])
    return float(np.max(np.abs(np.linalg.eigvals(step_map))))


def stability_limit(integrator: Integrator, mode: Mode, tolerance: float = 1e-12) -> float:
    """Largest dt (s) for which ``integrator`` keeps ``mode`` bounded (to a relative 10⁻⁸).

    0.0 if it is unstable at any dt (explicit Euler without damping; in practice:
    at 10⁻⁵/ω already), inf if it is stable at every dt up to 1000/ω (implicit Euler).
    Trial dts rise from 10⁻⁵/ω, `SCAN_PER_DECADE` a decade, to the first unstable
    one (spectral radius > 1 + ``tolerance``); the limit is bisected between it and
    the last stable one. Each trial is one step of the integrator.
    """
    if mode.omega == 0:
        return math.inf
    stable = 0.0
    for dt in np.logspace(-5, 3, 8 * SCAN_PER_DECADE + 1) / mode.omega:
        if spectral_radius(integrator, mode, dt) > 1.0 + tolerance:
            break
        stable = dt
    else:
        return math.inf
    if stable == 0.0:  # unstable for any practical dt
        return 0.0
    low, high = stable, dt
    while high - low > LIMIT_RTOL * low:
        middle = 0.5 * (low + high)
        if spectral_radius(integrator, mode, middle) > 1.0 + tolerance:
            high = middle
        else:
            low = middle
    return low


def max_stable_dt(
    body: Body, integrator: Integrator, forces: Sequence[Force] = (), x: np.ndarray | None = None
) -> float:
    """Predicted largest stable dt (s): `stability_limit` of the stiffest mode of ``body``.

    For undamped springs: 2/ω for symplectic Euler, velocity Verlet and
    Verlet (√(4 - 2λ)/ω with damping λ), 2√2/ω for RK4, 0 for explicit Euler,
    inf for implicit Euler.
    """
    return stability_limit(integrator, stiffest_mode(body, forces, x))


def describe_blowup(
    body: Body,
    integrator: Integrator,
    dt: float,
    forces: Sequence[Force],
    reference: np.ndarray,
    x: np.ndarray,
    x_new: np.ndarray,
    v_new: np.ndarray,
) -> str:
    """Explain a blow-up from x to (x_new, v_new) in a step of ``dt`` (s): which particle
    and spring, and dt against the limit predicted at the ``reference`` positions."""
    lines = []
    bad = ~(np.all(np.isfinite(x_new), axis=1) & np.all(np.isfinite(v_new), axis=1))
    if bad.any():
        first, others = int(np.flatnonzero(bad)[0]), int(bad.sum()) - 1
        also = f" (and {others} more)" if others else ""
        lines.append(f"particle {first}{also} got a non-finite position or velocity")
    else:
        speed = np.linalg.norm(v_new, axis=1)
        fastest = int(np.argmax(speed))
        lines.append(f"particle {fastest} moves at {speed[fastest]:.3g} length units a second")
    if body.n_springs:
        edges = body.edges()
        stretch = numpy_backend.vectors(edges, x)[1] / edges.rest_lengths
        worst = int(np.argmax(stretch))
        lines.append(
            f"spring {worst} (particles {edges.a[worst]}-{edges.b[worst]}) is at "
            f"{stretch[worst]:.3g}× its rest length"
        )
    lines.append(_against_the_limit(integrator, dt, stiffest_mode(body, forces, reference)))
    return "; ".join(lines)


def _against_the_limit(integrator: Integrator, dt: float, mode: Mode) -> str:
    """What dt (s) is against the predicted stable limit of ``integrator`` for ``mode``; the
    advice to change integrators only for one of the engine's own (a user's own integrator,
    such as one a course asks for, is to be fixed, not replaced)."""
    own = type(integrator).__module__ == Integrator.__module__
    name = type(integrator).__name__ if own else "your integrator"
    try:
        limit = stability_limit(integrator, mode)
    except Exception as error:  # a user's integrator that cannot step a one-mode system
        return f"(no stability prediction: the step of {name} failed on a test mode: {error!r})"
    if limit == 0.0:
        advice = (
            "use SymplecticEuler, Verlet, VelocityVerlet or ImplicitEuler, or add dashpots"
            if own
            else "compare its step with the scheme's equation, term by term"
        )
        return (
            f"{name} is unstable at any dt for these springs (its energy grows every step): "
            f"{advice}"
        )
    if dt > limit:
        return (
            f"dt = {dt:.3g} s is {dt / limit:.3g}× the predicted stable limit {limit:.3g} s "
            f"of {name} (stiffest mode ω = {mode.omega:.3g} rad/s, period {mode.period:.3g} s): "
            f"use dt < {0.9 * limit:.3g} s, softer springs{', or ImplicitEuler' if own else ''}"
        )
    return (
        f"dt = {dt:.3g} s is below the predicted linear limit {limit:.3g} s of {name}, so "
        "the blow-up comes from large deformations or contact (ground, sphere, drivers): "
        "reduce dt or the stiffness, or add damping"
    )
