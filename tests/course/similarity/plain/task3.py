"""Task 3 written a fourth way: the axis-angle matrix written out, a sparse incidence matrix."""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse

import msdlab as msd


def rotation_matrix(axis, angle_degrees):
    ux, uy, uz = np.asarray(axis, dtype=float) / math.hypot(*axis)
    c, s = math.cos(math.radians(angle_degrees)), math.sin(math.radians(angle_degrees))
    t = 1 - c
    return np.array(
        [
            [t * ux * ux + c, t * ux * uy - s * uz, t * ux * uz + s * uy],
            [t * ux * uy + s * uz, t * uy * uy + c, t * uy * uz - s * ux],
            [t * ux * uz - s * uy, t * uy * uz + s * ux, t * uz * uz + c],
        ]
    )


def rotate_layout(positions, axis, angle_degrees):
    grid = np.asarray(positions, dtype=float)
    rows = grid.reshape(-1, 3)
    mid = np.mean(rows, axis=0)
    turn = rotation_matrix(axis, angle_degrees)
    out = np.empty_like(rows)
    for r, p in enumerate(rows):
        out[r] = mid + turn.dot(p - mid)
    return out.reshape(grid.shape)


def spring_acceleration(positions, springs, rest_lengths, stiffness):
    pos = np.asarray(positions, dtype=float)
    edges = np.asarray(springs).reshape(-1, 2)
    lengths = np.asarray(rest_lengths, dtype=float).ravel()
    m = len(edges)
    rows = np.concatenate([np.arange(m), np.arange(m)])
    signs = np.concatenate([np.ones(m), -np.ones(m)])
    incidence = scipy.sparse.csr_matrix(
        (signs, (rows, np.concatenate([edges[:, 0], edges[:, 1]]))), shape=(m, len(pos))
    )
    d = incidence @ pos
    norm = np.linalg.norm(d, axis=1)
    coeff = np.divide(stiffness * (lengths - norm), norm, out=np.zeros(m), where=norm > 0)
    return np.asarray(incidence.T @ (coeff[:, None] * d))


def drop_rotated_cube(axis, angle_degrees, neighbours=(1,), steps=1500):
    h = 2.0 / N
    body = msd.Body.grid((N, N, N), spacing=h, stiffness=STIFFNESS, neighbours=neighbours)
    start = rotate_layout(body.positions, axis, angle_degrees)
    start = start + np.array([0.0, LIFT - start[:, 1].min(), 0.0])
    body.positions = start
    sim = msd.Simulation(body, msd.Verlet(), DT, [msd.Gravity(GRAVITY), msd.Ground(0.0)])
    for _ in range(steps):
        sim.step()
    return flatness(body.positions) / flatness(start)
