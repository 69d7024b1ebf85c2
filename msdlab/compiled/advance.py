"""The update loop: an integrator's update function compiled into one loop over the particles.

`compile_advance` turns an update such as `integrators.Verlet.update` into a
loop that computes a = F/m (plus gravity's g) and the update together, and adds
the spring forces the spring loops left pending in the same pass.
"""

from __future__ import annotations

from collections.abc import Callable

import numba

from .equations import acceleration


@numba.njit(cache=True, inline="always")
def particle_acceleration(i, q, forces, partial, field, masses, fixed):
    """a = (F + m·g)/m (m/s²) of particle i along q, 0 if fixed. F is ``forces`` (N, d)
    plus the threads' ``partial`` forces (T, N, d; T = 0 if none), added in the order
    the edge loop adds them (see `edges.spring_forces_parallel`)."""
    total = forces[i, q]
    for t in range(len(partial)):
        total += partial[t, i, q]
    return acceleration(total + masses[i] * field[q], masses[i], not fixed[i])


def compile_advance(update: Callable, threads: bool) -> Callable:
    """A loop over the particles doing a = (F + m·g)/m then ``update`` per coordinate.

    F is ``forces`` (N, d) plus the threads' ``partial`` forces (`particle_acceleration`);
    ``forces`` may be a view, such as the grid gather's forces by coordinate
    transposed (numba compiles the loop once for each layout it is given). The new
    state goes to ``x_new`` and ``v_new``. With ``threads`` the particles are split
    between the threads (each writes only its own rows). numba compiles it at its
    first call, which raises a numba error if it cannot.
    """
    scalar = numba.njit(update)

    @numba.njit(parallel=threads)
    def advance(x, v, forces, partial, field, masses, fixed, dt, coefficients, x_new, v_new):
        for i in numba.prange(len(masses)):
            for q in range(x.shape[1]):
                a = particle_acceleration(i, q, forces, partial, field, masses, fixed)
                x_new[i, q], v_new[i, q] = scalar(x[i, q], v[i, q], a, dt, *coefficients)

    return advance
