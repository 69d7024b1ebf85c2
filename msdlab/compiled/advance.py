"""The update loop: an integrator's update function compiled into one loop over the particles.

`compile_advance` turns an update such as `integrators.Verlet.update` into a loop that
computes a = F/m (plus gravity's g) and the update together, and adds the spring forces
the spring loops left pending in the same pass. The update is handed to numba as it is
written (`register_jitable`), and the loop calls it as a closure variable: numba inlines
it, and keys the loop's disk cache by the update's own code, so msdlab's integrators'
loops are compiled once per machine; a user's update is compiled once per process.
`advance_particles` keeps one loop per update for the process and runs it, or runs the
update on whole arrays if numba cannot compile it.
"""

from __future__ import annotations

import types
import warnings
from collections.abc import Callable

import numba
import numpy as np
from numba.extending import register_jitable

from .. import equations
from ..body import Body
from .equations import acceleration

# One compiled loop per update function, threaded or not, for the whole process; None for
# an update numba cannot compile (it runs on arrays).
_LOOPS: dict[tuple[Callable, bool], Callable | None] = {}


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
    rows = numba.prange if threads else range  # in the cache's key: one loop of each kind

    @numba.njit(parallel=threads, cache=cached(update))
    def advance(x, v, forces, partial, field, masses, fixed, dt, coefficients, x_new, v_new):
        for i in rows(len(masses)):
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


def advance_particles(
    update: Callable,
    body: Body,
    x: np.ndarray,
    v: np.ndarray,
    forces: np.ndarray,
    partial: np.ndarray,
    field: np.ndarray,
    dt: float,
    coefficients: tuple[float, ...],
    threads: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """The new positions and velocities: ``update`` with a = (F + m·g)/m, F = ``forces`` plus
    the ``partial`` forces, in the compiled loop of `compile_advance` (on the ``threads``
    or not). An update numba cannot compile warns once and runs on whole arrays."""
    if (update, threads) not in _LOOPS:
        _LOOPS[update, threads] = compile_advance(update, threads)
        if not isinstance(update, types.FunctionType) and (update, not threads) not in _LOOPS:
            warnings.warn(_not_compiled(update), RuntimeWarning, stacklevel=5)
    loop = _LOOPS[update, threads]
    if loop is not None:
        x_new, v_new = body.new_state()
        arrays = (x, v, forces, partial, field, body.masses, body.fixed)
        try:
            loop(*arrays, dt, coefficients, x_new, v_new)
            return x_new, v_new
        except numba.core.errors.NumbaError as error:
            _LOOPS[update, False] = _LOOPS[update, True] = None
            warnings.warn(
                f"numba cannot compile {update.__qualname__} ({type(error).__name__}); "
                "it runs on whole numpy arrays instead, with the same result, more slowly",
                RuntimeWarning,
                stacklevel=5,
            )
    for part in partial:  # on arrays, in the order of the compiled loop
        forces = forces + part
    masses, free = body.masses[:, None], ~body.fixed[:, None]
    return update(
        x, v, equations.acceleration(forces + masses * field, masses, free), dt, *coefficients
    )


def _not_compiled(update: Callable) -> str:
    """Why the update ``update``, not a plain function, runs on arrays, and how to compile it."""
    name = getattr(update, "__qualname__", type(update).__name__)
    fix = (
        "make it a @staticmethod (an update takes x, v, a, dt and coefficients, not self)"
        if isinstance(update, types.MethodType)
        else "pass a plain function def update(x, v, a, dt, *coefficients)"
    )
    return (
        f"numba compiles only plain functions, and the update {name} is a "
        f"{type(update).__name__}: it runs on whole numpy arrays instead, with the same "
        f"result, more slowly; to compile it, {fix}"
    )
