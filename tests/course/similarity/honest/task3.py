"""Task 3 written a second way: a quaternion, einsum, np.add.at over all springs at once."""

from __future__ import annotations

import numpy as np

import msdlab as msd

N, STIFFNESS, DT, GRAVITY, LIFT = 4, 0.5, 0.1, (0.0, -0.001, 0.0), 0.05


def rotation_matrix(axis, angle_degrees):
    u = np.asarray(axis, dtype=float)
    u = u / np.sqrt(u @ u)
    half = np.deg2rad(angle_degrees) / 2
    w, (x, y, z) = np.cos(half), np.sin(half) * u  # the unit quaternion of the rotation
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def rotate_layout(positions, axis, angle_degrees):
    pts = np.asarray(positions, dtype=float)
    centre = pts.reshape(-1, 3).mean(axis=0)
    turn = rotation_matrix(axis, angle_degrees)
    return np.einsum("ij,...j->...i", turn, pts - centre) + centre


def spring_acceleration(positions, springs, rest_lengths, stiffness):
    pos = np.asarray(positions, dtype=float)
    pairs = np.asarray(springs).reshape(-1, 2)
    rest = np.asarray(rest_lengths, dtype=float).reshape(-1)
    delta = pos[pairs[:, 0]] - pos[pairs[:, 1]]
    dist = np.sqrt((delta**2).sum(axis=1))
    scale = np.zeros_like(dist)
    apart = dist > 0
    scale[apart] = stiffness * (rest[apart] - dist[apart]) / dist[apart]
    force = scale[:, None] * delta
    out = np.zeros_like(pos)
    np.add.at(out, pairs[:, 0], force)
    np.subtract.at(out, pairs[:, 1], force)
    return out


def drop_rotated_cube(axis, angle_degrees, neighbours=(1,), steps=1500):
    cube = msd.Body.grid((N, N, N), spacing=2.0 / N, stiffness=STIFFNESS, neighbours=neighbours)
    turned = rotate_layout(cube.positions, axis, angle_degrees)
    turned[:, 1] += LIFT - turned[:, 1].min()
    cube.positions = turned
    start = flatness(turned)
    forces = [msd.Gravity(GRAVITY), msd.Ground(0.0)]
    msd.Simulation(cube, msd.Verlet(), DT, forces).run(steps=steps, record_every=steps)
    return flatness(cube.positions) / start
