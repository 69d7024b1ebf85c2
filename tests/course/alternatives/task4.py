"""Task 4 written differently: loops, springs stored as (j, i), another order."""

from __future__ import annotations

import itertools
import math
import time

import numpy as np

import msdlab as msd


def neighbour_offsets(squared_distances=(1, 2, 3)):
    return np.array(
        [
            o
            for o in itertools.product((1, 0, -1), repeat=3)
            if sum(c * c for c in o) in set(squared_distances)
        ]
    )


def grid_springs(shape, spacing, squared_distances=(1, 2, 3)):
    nx, ny, nz = shape
    pairs, rest = [], []
    for i, j, k in itertools.product(range(nx), range(ny), range(nz)):
        here = (i * ny + j) * nz + k
        for di, dj, dk in neighbour_offsets(squared_distances).tolist():
            p, q, r = i + di, j + dj, k + dk
            if 0 <= p < nx and 0 <= q < ny and 0 <= r < nz:
                there = (p * ny + q) * nz + r
                if there < here:  # each spring once, stored as (larger, smaller)
                    pairs.append((here, there))
                    rest.append(spacing * math.sqrt(di * di + dj * dj + dk * dk))
    return np.array(pairs, dtype=np.int64).reshape(-1, 2), np.array(rest)


def drop_rotated_cube(angle_degrees, axis, squared_distances=(1, 2, 3), steps=1500):
    body = msd.Body.grid((4, 4, 4), spacing=0.5, neighbours=())
    springs, rest = grid_springs((4, 4, 4), 0.5, squared_distances)
    body.add_springs(springs, 0.5, rest)
    body.rotate(msd.rotation_matrix(angle_degrees, axis))
    body.positions[:, 1] += 0.05 - body.positions[:, 1].min()

    def thickness():
        centred = body.positions - body.positions.mean(axis=0)
        return math.sqrt(max(np.linalg.eigvalsh(centred.T @ centred / len(centred))[0], 0.0))

    before = thickness()
    forces = [msd.Gravity((0.0, -0.001, 0.0)), msd.Ground(0.0)]
    simulation = msd.Simulation(body, msd.Verlet(), 0.1, forces)
    for _ in range(steps):
        simulation.step()
    return thickness() / before


def step_cost(n, squared_distances=(1, 2, 3), steps=20):
    body = msd.Body.grid((n, n, n), spacing=2.0 / n, neighbours=())
    springs, rest = grid_springs((n, n, n), 2.0 / n, squared_distances)
    body.add_springs(springs, 0.5, rest)
    simulation = msd.Simulation(body, msd.Verlet(), 0.1, [msd.Gravity((0.0, -0.001, 0.0))])
    start = time.process_time()
    for _ in range(steps):
        simulation.step()
    return body.n_springs, (time.process_time() - start) / steps
