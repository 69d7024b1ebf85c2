"""Task 4 written a fourth way: offsets counted in base 3, a padded index grid, timed steps."""

from __future__ import annotations

import math
import time

import numpy as np

import msdlab as msd


def neighbour_offsets(squared_distances=(1, 2, 3)):
    wanted = set(squared_distances)
    found = []
    for code in range(27):
        o = (code // 9 - 1, code // 3 % 3 - 1, code % 3 - 1)
        if o[0] ** 2 + o[1] ** 2 + o[2] ** 2 in wanted:
            found.append(o)
    return np.array(found, dtype=int).reshape(-1, 3)


def grid_springs(shape, spacing, squared_distances=(1, 2, 3)):
    nx, ny, nz = (int(s) for s in shape)
    ids = np.arange(nx * ny * nz).reshape(nx, ny, nz)
    padded = np.pad(ids, 1, constant_values=-1)  # -1: no particle beyond the border
    edges, rests = [], []
    for o in neighbour_offsets(squared_distances):
        if tuple(o) < tuple(-o):  # o and -o give the same springs
            continue
        moved = padded[1 + o[0] : 1 + o[0] + nx, 1 + o[1] : 1 + o[1] + ny, 1 + o[2] : 1 + o[2] + nz]
        ok = moved >= 0
        edges.append(np.column_stack([ids[ok], moved[ok]]))
        rests.append(np.full(int(ok.sum()), spacing * math.sqrt(int(o @ o))))
    return np.vstack(edges), np.concatenate(rests)


def drop_rotated_cube(axis, angle_degrees, squared_distances=(1, 2, 3), steps=1500):
    links, natural = grid_springs((N, N, N), 2.0 / N, squared_distances)
    pts = grid_positions((N, N, N), 2.0 / N)
    turn = msd.rotation_matrix(angle_degrees, axis)
    centre = pts.mean(axis=0)
    pts = np.array([centre + turn @ (p - centre) for p in pts])
    pts[:, 1] -= pts[:, 1].min() - LIFT
    thin_before = flatness(pts)
    cube = msd.Body.from_arrays(pts, links, stiffness=STIFFNESS, rest_lengths=natural)
    sim = msd.Simulation(cube, msd.Verlet(), DT, [msd.Gravity(GRAVITY), msd.Ground(0.0)])
    for _ in range(steps):
        sim.step()
    return flatness(cube.positions) / thin_before


def step_cost(n, squared_distances=(1, 2, 3), steps=20):
    h = 2.0 / n
    links, natural = grid_springs((n, n, n), h, squared_distances)
    grid = grid_positions((n, n, n), h)
    cube = msd.Body.from_arrays(grid, links, stiffness=STIFFNESS, rest_lengths=natural)
    sim = msd.Simulation(cube, msd.Verlet(), DT, [msd.Gravity(GRAVITY)])
    timings = []
    for _ in range(steps):
        tick = time.perf_counter()
        sim.step()
        timings.append(time.perf_counter() - tick)
    return int(links.shape[0]), sum(timings) / len(timings)
