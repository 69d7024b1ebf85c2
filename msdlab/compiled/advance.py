"""The update loop: an integrator's update function compiled into one loop over the particles.

`compile_advance` turns an update such as `integrators.verlet_update` into a
loop that computes a = F/m (plus gravity's g) and the update together, and adds
the spring forces the spring loops left pending in the same pass. `accelerations`
is that loop without an update: a = F/m (plus g) alone.
"""

from __future__ import annotations

from collections.abc import Callable

import numba

from .equations import acceleration


@numba.njit(cache=True)
def divide_by_masses(forces, masses, fixed):
    """Turn forces (N, d) into accelerations in place: a = F/m, and 0 for fixed particles."""
    for i in range(len(masses)):
        for q in range(forces.shape[1]):
            forces[i, q] = acceleration(forces[i, q], masses[i], not fixed[i])


@numba.njit(cache=True, inline="always")
def gathered_force(i, q, forces, pending):
    """Force (N) on particle i along q when the grid gather's forces by coordinate are all
    of it: ``by_coordinate[q, pad + i]`` of ``pending`` (see `compile_advance`)."""
    _, by_coordinate, pad = pending
    return by_coordinate[q, pad + i]


@numba.njit(cache=True, inline="always")
def summed_force(i, q, forces, pending):
    """Force (N) on particle i along q: ``forces`` plus the threads' partial forces of
    ``pending``, in the order the edge loop adds them (see `compile_advance`)."""
    partial = pending[0]
    total = forces[i, q]
    for t in range(len(partial)):
        total += partial[t, i, q]
    return total


@numba.njit(cache=True, inline="always")
def particle_acceleration(i, q, forces, pending, field, masses, fixed):
    """a = (F + m·g)/m (m/s²) of particle i along q, 0 if fixed, F from ``forces`` and the
    spring forces ``pending`` (`gathered_force` or `summed_force`)."""
    gathered = len(pending[1]) > 0
    total = (
        gathered_force(i, q, forces, pending) if gathered else summed_force(i, q, forces, pending)
    )
    return acceleration(total + masses[i] * field[q], masses[i], not fixed[i])


@numba.njit(cache=True)
def accelerations(forces, pending, field, masses, fixed, out):
    """Write into ``out`` (N, d) every particle's `particle_acceleration` (m/s²)."""
    for i in range(len(masses)):
        for q in range(out.shape[1]):
            out[i, q] = particle_acceleration(i, q, forces, pending, field, masses, fixed)


@numba.njit(cache=True, parallel=True)
def accelerations_parallel(forces, pending, field, masses, fixed, out):
    """`accelerations`, the particles split between the threads."""
    for i in numba.prange(len(masses)):
        for q in range(out.shape[1]):
            out[i, q] = particle_acceleration(i, q, forces, pending, field, masses, fixed)


def compile_advance(update: Callable, threads: bool, gathered: bool) -> Callable:
    """A loop over the particles doing a = (F + m·g)/m then ``update`` per coordinate.

    ``pending`` = (partial, by_coordinate, pad) holds the spring forces not yet
    added up. With ``gathered``, F is the grid gather's forces by coordinate,
    particle i at ``by_coordinate[q, pad + i]`` (see `gather.gather_parallel`);
    else F is ``forces`` plus the threads' ``partial`` forces (T, N, d; T = 0 if
    none, see `edges.spring_forces_parallel`), in the order the edge loop adds
    them. The new state goes to ``x_new`` and ``v_new``. With ``threads`` the
    particles are split between the threads (each writes only its own rows).
    numba compiles it at its first call, which raises a numba error if it cannot.
    """
    scalar = numba.njit(update)
    force = gathered_force if gathered else summed_force

    @numba.njit(parallel=threads)
    def advance(x, v, forces, pending, field, masses, fixed, dt, coefficients, x_new, v_new):
        for i in numba.prange(len(masses)):
            for q in range(x.shape[1]):
                total = force(i, q, forces, pending) + masses[i] * field[q]
                a = acceleration(total, masses[i], not fixed[i])
                x_new[i, q], v_new[i, q] = scalar(x[i, q], v[i, q], a, dt, *coefficients)

    return advance
