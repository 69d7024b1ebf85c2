"""Task 3 written differently: np.add.at, a loop over springs, matrix exponential rotation."""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg


def rotation_matrix(angle_degrees, axis):
    n = np.asarray(axis, dtype=float)
    n = n / np.linalg.norm(n)
    cross = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    return scipy.linalg.expm(math.radians(angle_degrees) * cross)


def rotate_layout(positions, angle_degrees, axis):
    positions = np.asarray(positions, dtype=float)
    flat = positions.reshape(-1, 3)
    centre = flat.sum(axis=0) / len(flat)
    turned = [rotation_matrix(angle_degrees, axis) @ (p - centre) + centre for p in flat]
    return np.array(turned).reshape(positions.shape)


def spring_acceleration(positions, springs, rest_lengths, stiffness):
    positions = np.asarray(positions, dtype=float)
    a = np.zeros_like(positions)
    for (i, j), rest in zip(np.asarray(springs).tolist(), np.asarray(rest_lengths).tolist()):
        d = positions[i] - positions[j]
        length = float(np.linalg.norm(d))
        if length == 0:
            continue
        f = stiffness * (rest - length) * d / length
        np.add.at(a, [i], f)
        np.add.at(a, [j], -f)
    return a


def drop_rotated_cube(angle_degrees, axis, neighbours=(1,), steps=1500):
    import msdlab as msd

    body = msd.Body.grid((4, 4, 4), spacing=0.5, stiffness=0.5, neighbours=neighbours)
    body.positions = rotate_layout(body.positions, angle_degrees, axis) + np.array([3.0, 7.0, -2.0])
    body.positions[:, 1] -= body.positions[:, 1].min() - 0.05
    eigen = np.linalg.eigvalsh(np.cov(body.positions.T, bias=True))
    before = math.sqrt(eigen[0])
    forces = [msd.Gravity((0.0, -0.001, 0.0)), msd.Ground()]
    msd.Simulation(body, msd.Verlet(), 0.1, forces).run(steps=steps)
    return math.sqrt(max(np.linalg.eigvalsh(np.cov(body.positions.T, bias=True))[0], 0)) / before
