"""The update loop: an integrator's update function compiled into one loop over the particles.

`compile_advance` turns an update such as `integrators.Verlet.update` into a loop that
computes a = F/m (plus gravity's g) and the update together, and adds the spring forces
the spring loops left pending in the same pass. The update is handed to numba as it is
written (`register_jitable`), and the loop calls it as a closure variable: numba inlines
it, and keys the loop's disk cache by the update's own code, so msdlab's integrators'
loops are compiled once per machine; a user's update is compiled once per process.
"""

from __future__ import annotations

import types
from collections.abc import Callable

import numba
from numba.extending import register_jitable

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


def compile_advance(update: Callable, threads: bool) -> Callable | None:
    """A loop over the particles doing a = (F + m·g)/m then ``update`` per coordinate.

    F is ``forces`` (N, d) plus the threads' ``partial`` forces (`particle_acceleration`);
    ``forces`` may be a view, such as the grid gather's forces by coordinate
    transposed (numba compiles the loop once for each layout it is given). The new
    state goes to ``x_new`` and ``v_new``. With ``threads`` the particles are split
    between the threads (each writes only its own rows). numba compiles it at its
    first call (or loads it from its disk cache, `cached`), which raises a numba error
    if it cannot. None if ``update`` is not a plain function (numba compiles only those).
    """
    if not isinstance(update, types.FunctionType):
        return None
    scalar = register_jitable(_copy(update))

    @numba.njit(parallel=threads, cache=cached(update))
    def advance(x, v, forces, partial, field, masses, fixed, dt, coefficients, x_new, v_new):
        for i in numba.prange(len(masses)):
            for q in range(x.shape[1]):
                a = particle_acceleration(i, q, forces, partial, field, masses, fixed)
                x_new[i, q], v_new[i, q] = scalar(x[i, q], v[i, q], a, dt, *coefficients)

    return advance


def cached(update: Callable) -> bool:
    """Whether the loop of ``update`` is kept in numba's disk cache: for msdlab's own updates.

    numba keys a cached loop by the update's code (its copy, `_copy`, is pickled by value),
    not by the functions it calls, which a user's module may change unseen.
    """
    return (getattr(update, "__module__", "") or "").startswith("msdlab.")


def _copy(update: Callable) -> Callable:
    """A copy of the function ``update`` (its code, globals and defaults): one that cannot be
    imported by name, so the loop's cache key holds its code, not its name."""
    return types.FunctionType(
        update.__code__, update.__globals__, update.__name__, update.__defaults__
    )
