"""The update loop: an integrator's update function compiled into one loop over the particles.

`compile_advance` turns an update such as `integrators.verlet_update` into a
loop that computes a = F/m (plus gravity's g) and the update together, adds
the spring forces the spring loops left pending, and can end the step
(`kernels.StepEnd`) in the same pass.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba

from .equations import acceleration, inverse_mass


@numba.njit(cache=True)
def divide_by_masses(forces, masses, fixed):
    """Turn forces (N, d) into accelerations in place: a = F/m, and 0 for fixed particles."""
    for i in range(len(masses)):
        inverse = inverse_mass(masses[i], not fixed[i])
        for q in range(forces.shape[1]):
            forces[i, q] = acceleration(forces[i, q], inverse)


def compile_advance(update: Callable, threads: bool) -> Callable:
    """A loop over the particles doing a = (F + m·g)/m then ``update`` per coordinate,
    and the end of the step (`kernels.StepEnd`) if ``floor`` says so.

    F is ``forces`` ((0, d): none) plus the spring forces not yet added to it, in the order the
    spring loops would add them: the threads' ``partial`` forces (T, N, d; T = 0
    if none, see `edges.spring_forces_parallel`), then the gather's forces by
    coordinate, particle i at ``by_coordinate[q, pad + i]`` (none if it has no
    rows, see `gather.gather_parallel`). ``floor`` is (normal (d,) or (0,), height,
    ending, damping): with ``ending`` the loop pins the fixed particles, sets
    ``under[i]`` (all False before) for the free particles under the plane, and
    returns the number of values that are not finite and, with ``damping``, the
    sum of m v·(v + v_new) over the particles not under the plane (else 0, 0).
    With ``threads`` the particles are split between the threads (each writes
    only its own rows). numba compiles it at its first call, which raises a
    numba error if it cannot.
    """
    scalar = numba.njit(update)

    @numba.njit(parallel=threads)
    def advance(
        x, v, forces, pending, field, masses, fixed, dt, coefficients, floor, x_new, v_new, under
    ):
        partial, by_coordinate, pad = pending
        normal, height, ending, damping = floor
        loaded = len(forces) > 0
        gathered = len(by_coordinate) > 0
        plane = ending and len(normal) > 0
        bad = 0
        work = 0.0
        for i in numba.prange(len(masses)):
            inverse = inverse_mass(masses[i], not fixed[i])
            pinned = ending and fixed[i]
            up = 0.0
            kick = 0.0
            for q in range(x.shape[1]):
                total = forces[i, q] if loaded else 0.0
                for t in range(len(partial)):
                    total += partial[t, i, q]
                if gathered:
                    total += by_coordinate[q, pad + i]
                a = acceleration(total + masses[i] * field[q], inverse)
                x_q, v_q = scalar(x[i, q], v[i, q], a, dt, *coefficients)
                if pinned:
                    x_q, v_q = x[i, q], 0.0
                if ending:
                    if not (math.isfinite(x_q) and math.isfinite(v_q)):
                        bad += 1
                    if plane:
                        up += x_q * normal[q]
                    if damping:
                        kick += v[i, q] * (v[i, q] + v_q)
                x_new[i, q], v_new[i, q] = x_q, v_q
            if plane and up < height and not fixed[i]:  # x·n summed as `Ground` sums it
                under[i] = True  # (a store for every particle costs 0.7 ms at 60³)
            elif damping:
                work += masses[i] * kick
        return bad, work

    return advance
