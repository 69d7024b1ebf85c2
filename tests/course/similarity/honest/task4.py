"""Task 4 written a second way: index arithmetic with np.indices, boolean masks at the border."""

from __future__ import annotations

import time

import numpy as np

import msdlab as msd

N, STIFFNESS, DT, GRAVITY, LIFT = 4, 0.5, 0.1, (0.0, -0.001, 0.0), 0.05


def neighbour_offsets(squared_distances=(1, 2, 3)):
    cube = np.indices((3, 3, 3)).reshape(3, -1).T - 1
    return cube[np.isin((cube**2).sum(axis=1), list(squared_distances))]


def grid_springs(shape, spacing, squared_distances=(1, 2, 3)):
    shape = tuple(int(n) for n in shape)
    coords = np.indices(shape).reshape(3, -1).T
    starts, ends, lengths = [], [], []
    for offset in neighbour_offsets(squared_distances):
        if offset[np.flatnonzero(offset)[0]] < 0:  # o and -o are one spring: keep the first
            continue
        target = coords + offset
        inside = np.all((target >= 0) & (target < np.array(shape)), axis=1)
        starts.append(np.ravel_multi_index(tuple(coords[inside].T), shape))
        ends.append(np.ravel_multi_index(tuple(target[inside].T), shape))
        lengths.append(np.full(int(inside.sum()), spacing * np.linalg.norm(offset)))
    return np.column_stack([np.concatenate(starts), np.concatenate(ends)]), np.concatenate(lengths)


def thinness(points):
    spread = points - points.mean(axis=0)
    return float(np.sqrt(max(np.linalg.eigvalsh(spread.T @ spread / len(spread)).min(), 0.0)))


def drop_rotated_cube(axis, angle_degrees, squared_distances=(1, 2, 3), steps=1500):
    h = 2.0 / N
    grid = np.indices((N, N, N)).reshape(3, -1).T * h
    middle = grid.mean(axis=0)
    turned = middle + (grid - middle) @ msd.rotation_matrix(angle_degrees, axis).T
    turned[:, 1] -= turned[:, 1].min() - LIFT
    links, rest = grid_springs((N, N, N), h, squared_distances)
    cube = msd.Body.from_arrays(turned, links, stiffness=STIFFNESS, rest_lengths=rest)
    world = msd.Simulation(cube, msd.Verlet(), DT, [msd.Gravity(GRAVITY), msd.Ground(0.0)])
    last = world.run(steps=steps, record_every=steps).positions[-1]
    return thinness(last) / thinness(turned)


def step_cost(n, squared_distances=(1, 2, 3), steps=20):
    links, rest = grid_springs((n, n, n), 2.0 / n, squared_distances)
    grid = np.indices((n, n, n)).reshape(3, -1).T * (2.0 / n)
    body = msd.Body.from_arrays(grid, links, stiffness=STIFFNESS, rest_lengths=rest)
    world = msd.Simulation(body, msd.Verlet(), DT, [msd.Gravity(GRAVITY)])
    began = time.perf_counter()
    for _ in range(steps):
        world.step()
    return len(links), (time.perf_counter() - began) / steps
