"""Independent references for the public checks: the template's given loop, engine runs, energies.

Nothing here is an answer to a task: the checks compare a submission with the
engine, with the template the students are given, or with analytic results and
conservation laws, and name the usual cause of a wrong answer from variants of
the engine's results. This module ships with the package; references that are
answers (for the hidden checks) stay with the instructor's checks.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

import msdlab as msd

from ..engine.backends.numpy import spring_forces

TEMPLATE_DT = 0.1
TEMPLATE_GRAVITY = (0.0, -0.001, 0.0)


def template_positions(shape: Sequence[int], spacing: float, origin: Sequence[float]) -> np.ndarray:
    """Grid positions (nx, ny, nz, 3): origin + spacing·(i, j, k)."""
    index = np.stack(np.meshgrid(*(np.arange(n) for n in shape), indexing="ij"), axis=-1)
    return np.asarray(origin, dtype=float) + spacing * index


def template_run(
    start: np.ndarray,
    steps: int,
    dt: float = TEMPLATE_DT,
    acceleration: Sequence[float] = TEMPLATE_GRAVITY,
    floor: float | None = 0.0,
) -> np.ndarray:
    """The template's loop from rest: three buffers, ``msd_kernel`` per step. Frames (steps+1, ...).

    Per step: v = (cur - old)/dt; v += dt·a; new = cur + dt·v; new.y = max(new.y, floor).
    """
    current = np.array(start, dtype=float)
    old = current.copy()
    frames = [current.copy()]
    a = np.asarray(acceleration, dtype=float)
    for _ in range(steps):
        v = (current - old) / dt
        v = v + dt * a
        new = current + dt * v
        if floor is not None:
            new[..., 1] = np.maximum(new[..., 1], floor)
        old, current = current, new
        frames.append(current.copy())
    return np.array(frames)


def grid_body(
    shape: Sequence[int],
    spacing: float,
    stiffness: float,
    neighbours: Sequence[int] = (1,),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
) -> msd.Body:
    """The engine's grid body: particle (i, j, k) is row ravel_multi_index((i, j, k), shape)."""
    return msd.Body.grid(shape, spacing, stiffness, neighbours=neighbours, origin=origin)


def spring_acceleration(body: msd.Body, x: np.ndarray) -> np.ndarray:
    """Acceleration (N, d) from the springs alone, eq. (1.1)-(1.2), by the engine."""
    force, _ = spring_forces(body, x, np.zeros_like(x))
    return force / body.masses[:, None]


def energies(
    body: msd.Body, frames: np.ndarray, dt: float, g: Sequence[float] | None = None
) -> np.ndarray:
    """Total energy (J) at frames 1 .. F-2 from positions only (central-difference velocities).

    Independent of how an integrator stores its velocity. ``g`` adds -Σ m g·x.
    """
    frames = np.asarray(frames, dtype=float)
    v = (frames[2:] - frames[:-2]) / (2 * dt)
    kinetic = 0.5 * np.einsum("n,fni,fni->f", body.masses, v, v)
    elastic = np.array([msd.elastic_energy(body, x) for x in frames[1:-1]])
    potential = 0.0
    if g is not None:
        potential = -np.einsum("n,fni,i->f", body.masses, frames[1:-1], np.asarray(g, float))
    return kinetic + elastic + potential


def flatness(positions: np.ndarray) -> float:
    """Thinnest extent of a cloud of points: √(smallest eigenvalue of its gyration tensor) (m)."""
    points = np.asarray(positions, dtype=float).reshape(-1, 3)
    centred = points - points.mean(axis=0)
    gyration = centred.T @ centred / len(points)
    return float(np.sqrt(max(np.linalg.eigvalsh(gyration)[0], 0.0)))


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random proper rotation matrix (3, 3)."""
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


# ----------------------------------------------------------------- typical mistakes, by the engine
# The checks name the usual cause of a wrong answer by comparing it with what the
# mistake gives. Each variant below is the engine's result, transformed or run on a
# changed body: none of them is an implementation of a task.


def spring_body(
    positions: np.ndarray, springs: np.ndarray, rest_lengths: np.ndarray | float, stiffness: float
) -> msd.Body:
    """The engine's body of unit-mass particles at ``positions`` joined by index pairs (E, 2)."""
    return msd.Body.from_arrays(
        np.asarray(positions, dtype=float),
        np.asarray(springs, dtype=np.int64).reshape(-1, 2),
        stiffness=stiffness,
        rest_lengths=rest_lengths,
    )


def force_of_each_spring(
    positions: np.ndarray, springs: np.ndarray, rest_lengths: np.ndarray | float, stiffness: float
) -> np.ndarray:
    """The force (E, 3) of every spring on its first end, eq. (1.2), unit masses.

    By the engine: every spring alone in a body of its own two particles.
    """
    springs = np.asarray(springs, dtype=np.int64).reshape(-1, 2)
    ends = np.asarray(positions, dtype=float)[springs.ravel()]
    own = np.arange(len(ends)).reshape(-1, 2)
    return spring_acceleration(spring_body(ends, own, rest_lengths, stiffness), ends)[0::2]


def one_sided_acceleration(
    positions: np.ndarray, springs: np.ndarray, rest_lengths: np.ndarray | float, stiffness: float
) -> np.ndarray:
    """Accelerations (N, 3) when each spring acts on its first end only (the reaction is lost).

    By the engine: the second end of every spring is a detached copy of that particle.
    """
    positions = np.asarray(positions, dtype=float)
    springs = np.asarray(springs, dtype=np.int64).reshape(-1, 2)
    n = len(positions)
    copies = n + np.arange(len(springs))
    body = spring_body(
        np.concatenate([positions, positions[springs[:, 1]]]),
        np.stack([springs[:, 0], copies], axis=1),
        rest_lengths,
        stiffness,
    )
    return spring_acceleration(body, body.positions)[:n]


def wrapped_border_pairs(shape: Sequence[int]) -> np.ndarray:
    """The extra springs (E, 2) that ``np.roll`` adds to a C-order grid: from the last
    particle of each line to the first (a typical mistake at the border)."""
    index = np.arange(int(np.prod(shape))).reshape(shape)
    pairs = [
        np.stack([np.take(index, -1, axis=axis).ravel(), np.take(index, 0, axis=axis).ravel()], 1)
        for axis, n in enumerate(shape)
        if n > 1  # a line of one particle would be joined to itself: no force
    ]
    return np.concatenate(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)


def task_constant(task: Any, name: str) -> float | None:
    """The number ``name`` (``STIFFNESS``, ``SPACING``, ``DT``) of a submission's task module:
    what its code uses where it ignores the argument of that name. None without a module,
    or where the module has no such number."""
    if task is None:
        return None
    try:
        value = getattr(task, name)
    except Exception:  # not there, or the submission's process failed: no such cause
        return None
    is_number = isinstance(value, (int, float, np.floating, np.integer))
    return float(value) if is_number and not isinstance(value, bool) else None


def spring_list_mistakes(
    positions: np.ndarray,
    springs: np.ndarray,
    rest_lengths: np.ndarray | float,
    stiffness: float,
    task: Any = None,
) -> dict[str, np.ndarray]:
    """Accelerations (N, 3) that typical mistakes in a sum of spring forces give, by cause
    (with the submission's ``task`` module, also its own STIFFNESS used for the argument)."""
    positions = np.asarray(positions, dtype=float)
    springs = np.asarray(springs, dtype=np.int64).reshape(-1, 2)
    rest = np.broadcast_to(np.asarray(rest_lengths, dtype=float), (len(springs),))
    right = spring_acceleration(spring_body(positions, springs, rest, stiffness), positions)
    one_sided = one_sided_acceleration(positions, springs, rest, stiffness)
    length = np.linalg.norm(positions[springs[:, 0]] - positions[springs[:, 1]], axis=1)
    unnormalised = spring_body(positions, springs, rest, 1.0)
    unnormalised.set_springs(stiffness=stiffness * np.maximum(length, 1e-300))  # k|d| (l - |d|) d̂
    count = np.bincount(springs.ravel(), minlength=len(positions)).astype(float)
    mistakes = {}
    constant = task_constant(task, "STIFFNESS")
    if constant is not None and not np.isclose(stiffness, constant):
        mistakes[
            f"the stiffness argument is ignored (your STIFFNESS = {constant:g} used instead "
            "of the k given)"
        ] = right * constant / stiffness
    mistakes |= {
        "-f_ij is never added to particle j: each spring acts on both of its ends": one_sided,
        "the force is not divided by the spring length: f_ij = k (l - |x_i - x_j|) times the "
        "UNIT vector (x_i - x_j)/|x_i - x_j|": spring_acceleration(unnormalised, positions),
        "the reaction on j has the same sign as the force on i: j gets -f_ij": (
            2 * one_sided - right
        ),
        "half of each spring force given to each end: particle i gets all of f_ij, j all "
        "of -f_ij": right / 2,
        "eq. (1.1) is the sum over the neighbours, not their average": right
        / np.maximum(count, 1)[:, None],
    }
    if len(rest) and not np.allclose(rest, rest[0]):
        mistakes["one rest length for every spring: each spring has its own l_ij"] = (
            spring_acceleration(spring_body(positions, springs, rest.mean(), stiffness), positions)
        )
    return mistakes


def axis_spring_mistakes(
    x: np.ndarray, spacing: float, stiffness: float, task: Any = None
) -> dict[str, np.ndarray]:
    """Accelerations (nx, ny, nz, 3) that typical mistakes in task 2 give, by cause (with the
    submission's ``task`` module, also its own SPACING and STIFFNESS used for the arguments)."""
    shape = x.shape[:3]
    flat = np.asarray(x, dtype=float).reshape(-1, 3)
    body = grid_body(shape, spacing, stiffness)
    edges = body.edges()
    springs = np.stack([edges.a, edges.b], axis=1)
    right = spring_acceleration(body, flat).reshape(x.shape)
    wrapped = spring_body(flat, wrapped_border_pairs(shape), spacing, stiffness)
    border = np.ones(shape, dtype=bool)
    border[tuple(slice(1, -1) if n > 2 else slice(0, 0) for n in shape)] = False
    along_z = springs[:, 1] - springs[:, 0] == 1  # C order: the last index is the fastest
    mistakes = {
        "the sign: eq. (1.2) is k (l - |x_i - x_j|) times the unit vector from x_j to x_i; "
        "with either factor reversed a stretched spring pushes its ends apart": -right,
        "np.roll (or a modulo index) wraps around the grid: border particles got springs "
        "to the opposite face": right + spring_acceleration(wrapped, flat).reshape(x.shape),
        "only one end of each spring gets its force: particle j needs -f_ij too (each "
        "particle has neighbours on both sides)": one_sided_acceleration(
            flat, springs, spacing, stiffness
        ).reshape(x.shape),
        "each spring is counted twice (once from each end, then its reaction added again)": (
            2 * right
        ),
        "border particles are skipped: particles on a face, edge or corner have 5, 4 or 3 "
        "neighbours and still feel them": np.where(border[..., None], 0.0, right),
    }
    if not np.isclose(spacing, 1.0):
        mistakes[
            "rest length 1 in world units: 'rest length 1' means one grid spacing, "
            "l = the spacing given"
        ] = spring_acceleration(spring_body(flat, springs, 1.0, stiffness), flat).reshape(x.shape)
    constant = task_constant(task, "SPACING")
    if constant is not None and not np.isclose(spacing, constant):
        mistakes[
            f"the spacing argument is ignored (your SPACING = {constant:g} used as the rest "
            "length instead of the spacing given)"
        ] = spring_acceleration(spring_body(flat, springs, constant, stiffness), flat).reshape(
            x.shape
        )
    if along_z.any() and not along_z.all():
        mistakes["only two of the three axes have springs: loop over all three"] = (
            spring_acceleration(spring_body(flat, springs[~along_z], spacing, stiffness), flat)
        ).reshape(x.shape)
    for cause, values in spring_list_mistakes(flat, springs, spacing, stiffness, task).items():
        mistakes.setdefault(cause, values.reshape(x.shape))
    return mistakes
