"""The equations of the engine, each written once.

Every function here is plain arithmetic, so it works on numbers and, by numpy
broadcasting, on whole arrays. The numpy kernel (`msdlab.engine.backends.numpy`) calls them
on arrays of all springs or particles; the numba kernel (`msdlab.engine.backends.numba`)
compiles the same functions and calls them on one spring or one coordinate
at a time. `Spring`, the kernels and the integrators all use these, so there
is no second copy of a formula to keep in step.

Equation numbers are those of the course brief.
"""

from __future__ import annotations

import numpy as np

Vector = tuple[float, float, float]  # three coordinates, the third 0 in 2-D


def spring_force(
    stiffness: float,
    rest: float,
    damping: float,
    d: tuple[float, float, float],
    w: tuple[float, float, float] | None,
) -> tuple[tuple[float, float, float], float, float]:
    """Force (N) on end ``a`` of a spring from end ``b``: eq. (1.2) plus the dashpot, a vector;
    with the length |d| (m) and the lengthening rate ṡ (m/s) it was computed from.

    ``d`` = x_a - x_b (m) and ``w`` = v_a - v_b (m/s), three coordinates each (0 for
    the third in 2-D; ``w`` may be None where there is no dashpot)::

        n = d / |d|,   ṡ = w·n,   f_a = [k (l - |d|) - c ṡ] n,   f_b = -f_a

    ṡ is how fast the spring lengthens. Coincident ends (d = 0) have no
    direction and get no force. The terms are `spring_state`'s; the derivative is
    `spring_jacobian`.
    """
    length, _, rate, scale = spring_state(stiffness, rest, damping, d, w)  # scale: |f_a|/|d|
    return (scale * d[0], scale * d[1], scale * d[2]), length, rate


def spring_state(
    stiffness: float,
    rest: float,
    damping: float,
    d: tuple[float, float, float],
    w: tuple[float, float, float] | None = None,
) -> tuple[float, float, float, float]:
    """The terms of `spring_force`, each written once for every kernel: the length |d| (m),
    the length n = d/|d| divides by (m), the lengthening rate ṡ = w·n (m/s) and |f_a|/|d|
    (N/m), so that f_a = (|f_a|/|d|)·d with the tension k (l - |d|) - c ṡ.

    ``d`` = x_a - x_b, ``w`` = v_a - v_b (three coordinates each), or None for a spring
    without a dashpot (ṡ = 0; compiled loops then skip reading the velocities).
    Coincident ends (d = 0) have no direction: n is divided by 1 there, so n, ṡ and the
    force are 0.
    """
    length = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    safe = length + (length == 0.0)  # 1 where d = 0
    rate = 0.0 if w is None else (w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / safe
    tension = stiffness * (rest - length) - damping * rate  # positive: pushes the ends apart
    return length, safe, rate, tension / safe


def spring_jacobian(
    stiffness: float, transverse: float, damping: float, n_i: float, n_j: float, same: float
) -> tuple[float, float]:
    """Entry (i, j) of the derivative of `spring_force`: -∂f_a/∂x_a, the stiffness block
    B = k n nᵀ + k_t (I - n nᵀ) (N/m), and -∂f_a/∂v_a, the dashpot block C = c n nᵀ
    (N·s/m), for the direction n = d/|d| (``n_i``, ``n_j`` its coordinates; ``same`` 1
    where i = j, else 0) and k_t = `transverse_stiffness`. A spring adds -B and -C on its
    (a, a) and (b, b) blocks of ∂F/∂x and ∂F/∂v, +B and +C on (a, b) and (b, a).
    """
    along = n_i * n_j
    return (stiffness - transverse) * along + transverse * same, damping * along


def spring_energy(stiffness: float, rest: float, length: float) -> float:
    """Elastic energy ½ k (|x_a - x_b| - l)² (J) of a spring of the given length."""
    return 0.5 * stiffness * (length - rest) ** 2


def dashpot_power(damping: float, rate: float) -> float:
    """Power c ṡ² (W) a dashpot takes out when its spring lengthens at ``rate`` ṡ (m/s)."""
    return damping * rate**2


def transverse_stiffness(stiffness: float, rest: float, length: float, safe: float) -> float:
    """Stiffness k·max(0, 1 - l/|d|) (N/m) of a spring across its direction n.

    With it the spring's Jacobian block is B = k n nᵀ + k_t (I - n nᵀ); it is 0
    for a compressed spring (as Baraff & Witkin do, so that -∂F/∂x stays
    positive semi-definite). Coincident ends (|d| = 0, divided by ``safe`` = 1 instead, see
    `spring_state`) have no direction: k_t = k, B = k I.
    """
    return stiffness * np.maximum(0.0, 1.0 - rest * (length > 0.0) / safe)


def acceleration(force: float, mass: float, free: bool) -> float:
    """Newton's second law a = F/m (m/s²) for a free particle, 0 for a fixed one: the
    inverse mass of a fixed particle is 0, so no force moves it."""
    return force * (free / mass)


def kinetic_energy(masses: np.ndarray, velocities: np.ndarray) -> float:
    """½ Σ m |v|² (J) of particles of ``masses`` (N,) moving at ``velocities`` (N, d)."""
    return float(0.5 * np.sum(masses * np.einsum("ij,ij->i", velocities, velocities)))


def kick_work(mass: float, kick: float, v_before: float, v_after: float) -> float:
    """Work (J) of a velocity change ``kick`` Δv (m/s) given to a particle of ``mass`` (kg)
    during a step, along one coordinate: ½ m Δv (v_before + v_after).

    The force m·Δv/dt does work at the particle's velocity at the time it acts, the mean
    of the step's start and end velocities: for position Verlet, (x(t+dt) - x(t-dt))/2dt.
    Numbers or arrays of them; a contact's, the ground's and a velocity factor's work.
    """
    return 0.5 * mass * kick * (v_before + v_after)


def contact_work(
    masses: np.ndarray, kick: np.ndarray, v_before: np.ndarray, v_after: np.ndarray
) -> float:
    """Work (J) a contact did in one step: Σ `kick_work`, Σ m Δv·(v_before + v_after)/2.

    ``kick`` (M, d) is the velocity change Δv the contact gave each particle in
    the step (its impulse per mass, m/s); ``v_before`` and ``v_after`` are the
    velocities at the start and the end of the step. A contact that holds a
    particle at rest does no work; one that stops a particle does negative work.
    """
    return float(np.sum(kick_work(masses[:, None], kick, v_before, v_after)))


def ground_contact(
    mass: float,
    position: Vector,
    above: float,
    velocity: Vector,
    start: Vector,
    start_velocity: Vector,
    normal: Vector,
    height: float,
    dt: float,
    keep: float,
) -> tuple[Vector, Vector, float]:
    """The ground's contact with a particle that ended a step below its plane n·x = h: the
    particle put back on the plane, its new velocity (m/s) and the energy (J) the ground
    removed in the step.

    ``position`` x and ``velocity`` v are the step's end, ``start`` and ``start_velocity``
    its start, ``normal`` n a unit vector, three coordinates each (0 for the third in
    2-D); ``above`` is x·n, which found the particle below. The particle is projected
    along n onto the plane, its normal speed becomes what position Verlet implies (no
    bounce, no sticking), its tangential velocity is kept times ``keep`` = 1 - friction::

        x' = x + (h - x·n) n,   v_t = v - (v·n) n,   ṡ = (x' - x_start)·n / dt,
        v' = keep·v_t + ṡ n

    Both x' and v_t are the projection I - n nᵀ, their derivative (∂x'/∂x = ∂v_t/∂v).
    Removed: friction's loss (1 - keep²)·½ m |v_t|² minus the contact's work, `kick_work`
    of the kick ṡ - v·n (written out here: the step's trace stays short).
    """
    n0, n1, n2 = normal
    depth = height - above
    x0, x1, x2 = position[0] + depth * n0, position[1] + depth * n1, position[2] + depth * n2
    landing = velocity[0] * n0 + velocity[1] * n1 + velocity[2] * n2  # v·n at the end
    moved = (x0 - start[0]) * n0 + (x1 - start[1]) * n1 + (x2 - start[2]) * n2
    before = start_velocity[0] * n0 + start_velocity[1] * n1 + start_velocity[2] * n2
    t0, t1, t2 = velocity[0] - landing * n0, velocity[1] - landing * n1, velocity[2] - landing * n2
    normal_speed = moved / dt
    work = 0.5 * mass * (normal_speed - landing) * (before + normal_speed)  # `kick_work`'s
    removed = 0.5 * (1.0 - keep * keep) * mass * (t0 * t0 + t1 * t1 + t2 * t2) - work
    v0, v1, v2 = (
        keep * t0 + normal_speed * n0,
        keep * t1 + normal_speed * n1,
        keep * t2 + normal_speed * n2,
    )
    return (x0, x1, x2), (v0, v1, v2), removed


def damping_kick_work(mass: float, factor: float, v_before: float, v_after: float) -> float:
    """Work (J) of the kick a velocity ``factor`` gives a particle of ``mass`` (kg) at the start
    of a step, along one coordinate: Δv = (factor - 1)·v_before (∂Δv/∂v_before = factor - 1),
    `kick_work` with the step's end velocity v_after; numbers or arrays of them::

        W = ½ m (factor - 1) v_before (v_before + v_after)
    """
    return 0.5 * mass * ((factor - 1.0) * v_before) * (v_before + v_after)  # `kick_work`'s


def damping_work(
    masses: np.ndarray, v_before: np.ndarray, v_after: np.ndarray, factor: float
) -> float:
    """Energy (J) a velocity factor per step takes out of a leapfrog step.

    The step scales the velocity it starts from, v_before, by ``factor`` before
    the forces act (damped Verlet, eq. 1.4: factor = 1 - λ): a kick whose work is
    `damping_kick_work`, with the step's end velocity v_after, summed over the particles of
    ``masses`` (N,), velocities (N, d). Booking (1 - factor²)·½ Σ m v_before² instead
    misses the work against the forces' kick and leaves a first-order drift.
    """
    return -float(np.sum(damping_kick_work(masses[:, None], factor, v_before, v_after)))
