"""Independent references for the checks: the template written again, engine runs, energies.

Nothing here comes from a task file: the checks compare a submission with
these, with the engine, or with analytic results and conservation laws.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

import msdlab as msd

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


def first_floor_contact(y0: float, dt: float, g: float, limit: int = 1_000_000) -> int:
    """Steps of the template until a particle at rest at height y0 first reaches y <= 0."""
    y_old = y = float(y0)
    for step in range(1, limit + 1):
        v = (y - y_old) / dt + dt * g
        y_old, y = y, y + dt * v
        if y <= 0.0:
            return step
    raise ValueError(f"no floor contact within {limit} steps (y0 = {y0}, dt = {dt}, g = {g})")


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
    force, _ = msd.kernels.spring_forces(body, x, np.zeros_like(x))
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
    elastic = np.array([msd.kernels.elastic_energy(body, x) for x in frames[1:-1]])
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


def drop_rotated_cube(
    axis: Sequence[float],
    angle_degrees: float,
    neighbours: Sequence[int],
    n: int = 4,
    steps: int = 1500,
    stiffness: float = 0.5,
    lift: float = 0.05,
) -> float:
    """Flatness after / before of an n³ cube (spacing 2/n) rotated, put on the floor and run.

    Template setting: msd.Verlet(), dt = 0.1, gravity (0, -0.001, 0), floor y = 0;
    the rotated cube is shifted up so its lowest particle is at y = ``lift``.
    """
    body = grid_body((n, n, n), 2.0 / n, stiffness, neighbours)
    body.rotate(msd.rotation_matrix(angle_degrees, axis))
    body.positions[:, 1] += lift - body.positions[:, 1].min()
    before = flatness(body.positions)
    forces = [msd.Gravity(TEMPLATE_GRAVITY), msd.Ground(0.0)]
    msd.Simulation(body, msd.Verlet(), TEMPLATE_DT, forces).run(steps=steps, record_every=steps)
    return flatness(body.positions) / before


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random proper rotation matrix (3, 3)."""
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def pair_acceleration(
    positions: np.ndarray,
    pairs: np.ndarray,
    rest_lengths: np.ndarray | float,
    stiffness: float,
    reaction: bool = True,
) -> np.ndarray:
    """Eq. (1.1)-(1.2) over index pairs (E, 2) of positions (N, 3), unit masses.

    ``reaction=False`` leaves out the force on the second particle of each pair
    (a typical mistake that the checks recognise).
    """
    positions = np.asarray(positions, dtype=float)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    d = positions[pairs[:, 0]] - positions[pairs[:, 1]]
    length = np.linalg.norm(d, axis=1, keepdims=True)
    direction = np.divide(d, length, out=np.zeros_like(d), where=length > 0)
    rest = np.broadcast_to(np.asarray(rest_lengths, dtype=float), (len(pairs),))[:, None]
    f = stiffness * (rest - length) * direction
    a = np.zeros_like(positions)
    np.add.at(a, pairs[:, 0], f)
    if reaction:
        np.subtract.at(a, pairs[:, 1], f)
    return a


def axis_pairs(shape: Sequence[int], periodic: bool = False) -> np.ndarray:
    """Index pairs (E, 2) of axis neighbours (i, i + 1 along each axis) of a C-order grid.

    ``periodic=True`` also joins the last particle of each line to the first,
    as ``np.roll`` does (a typical mistake at the border).
    """
    index = np.arange(int(np.prod(shape))).reshape(shape)
    pairs = []
    for axis, n in enumerate(shape):
        if periodic:
            pairs.append(np.stack([index.ravel(), np.roll(index, -1, axis).ravel()], axis=1))
        elif n > 1:
            first = np.take(index, np.arange(n - 1), axis=axis).ravel()
            second = np.take(index, np.arange(1, n), axis=axis).ravel()
            pairs.append(np.stack([first, second], axis=1))
    return np.concatenate(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)


def axis_spring_mistakes(x: np.ndarray, spacing: float, stiffness: float) -> dict[str, np.ndarray]:
    """Accelerations (nx, ny, nz, 3) that typical mistakes in task 2 give, by cause."""
    shape = x.shape[:3]
    flat = x.reshape(-1, 3)
    pairs = axis_pairs(shape)
    right = pair_acceleration(flat, pairs, spacing, stiffness).reshape(x.shape)
    border = np.ones(shape, dtype=bool)
    border[tuple(slice(1, -1) if n > 2 else slice(0, 0) for n in shape)] = False
    mistakes = {
        "the sign: eq. (1.2) is k (l - |x_i - x_j|) times the unit vector from x_j to x_i; "
        "with either factor reversed a stretched spring pushes its ends apart": -right,
        "np.roll (or a modulo index) wraps around the grid: border particles got springs "
        "to the opposite face": pair_acceleration(
            flat, axis_pairs(shape, periodic=True), spacing, stiffness
        ).reshape(x.shape),
        "only one end of each spring gets its force: particle j needs -f_ij too (each "
        "particle has neighbours on both sides)": pair_acceleration(
            flat, pairs, spacing, stiffness, reaction=False
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
            f"l = spacing = {spacing:g}"
        ] = pair_acceleration(flat, pairs, 1.0, stiffness).reshape(x.shape)
    return mistakes
