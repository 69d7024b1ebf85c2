"""The numba backend: `NumbaKernel`, the methods of `backends.numpy.NumpyKernel` on compiled loops.

The same `msdlab.engine.equations`, compiled (`numba.equations`: the equations' own functions
handed to numba), applied one spring or particle at a time, in this file's loops: the edge
loop over an edge list's springs sorted by their ends (forces, energy, Jacobian blocks),
the finiteness check and the damping work, the ground's clamp, and an integrator's update
compiled into one loop over the particles. A lattice (the springs of `Body.grid`) goes to
the backend's second loop, by neighbour offset (`numba.lattice`).

To step through these loops in a debugger, or print inside them, run them as plain Python
with ``NUMBA_DISABLE_JIT=1`` (same results, slowly); to step through the readable
equations instead, set ``MSDLAB_KERNEL=numpy`` (or start a debugger: a simulation that
asked for no kernel steps on the numpy kernel while a debugger traces it).
"""

from __future__ import annotations

import types
import warnings
from collections.abc import Callable

import numba
import numpy as np
from numba.extending import register_jitable

from ... import equations
from ...model.springs import EdgeSprings
from ..contract import Advanced, Jacobians, SpringSums
from ..layout import Layout
from .equations import (
    acceleration,
    damping_kick_work,
    dashpot_power,
    ground_contact,
    separation,
    spring_energy,
    spring_jacobian,
    spring_state,
    transverse_stiffness,
)
from .lattice import (
    NO_PLAN,
    gather_parallel,
    gather_serial,
    grid_sum_parallel,
    grid_sum_serial,
    padded_shape,
    plan,
)

# Below this many springs (particles for the update, `PARALLEL_MIN_PARTICLES`) one thread is
# faster than waking the others.
PARALLEL_MIN_SPRINGS = 50_000

# The gather wakes the threads four times a step: it waits for more springs (about 28³ grid).
PARALLEL_MIN_GATHERED = 250_000

PARALLEL_MIN_PARTICLES = 20_000  # from here a pass over the state runs on the threads
# The reductions' own name for it: numba freezes a global into a compiled loop (and its disk
# cache), so a test lowering PARALLEL_MIN_PARTICLES for the update loop must not reach them.
_REDUCTIONS_MIN_PARTICLES = PARALLEL_MIN_PARTICLES
BLOCK = 4096  # particles per partial sum of the reductions


# The edge loop. For each spring it computes the length, the force along it (eq. 1.2 plus
# the dashpot), adds it to particle a and its opposite to particle b (eq. 1.1), and keeps
# the largest stretch |d|/l and the dashpot power on the way, with no temporary arrays.
# Large bodies split the springs between the threads, each summing into its own force
# buffer (no two threads write the same memory; the first one writes the result), and the
# buffers are then added per particle. The springs are visited sorted by their ends
# (`NumbaKernel._sorted_edges`), so memory is read in order whatever order they were added
# in; along the springs of one first end, its position and force stay in registers.


@numba.njit(cache=True, inline="always")
def _add_spring_forces(x, v, a, b, k, rest, c, first, stop, out, three):
    """Add the forces of springs ``first`` to ``stop - 1`` to ``out``, (N, 3) if ``three``
    else (N, 2). Returns the largest stretch |d|/l and the dashpot power (W) of those springs.

    Along a run of springs with the same end a, a's position and force stay in
    registers: its force is summed in the same order as in memory, so the sums do
    not change. |d|, ṡ and the force are `equations.spring_state`'s, computed once for
    the force, the stretch and the dashpot power (the numpy kernel's operations, so its
    bits).
    """
    peak = np.zeros(1)  # the stretch, in memory: a register would make it divide every time
    power = 0.0
    if first >= stop:
        return 0.0, power
    i = a[numba.uint64(first)]
    y0, y1, y2 = x[i, 0], x[i, 1], x[i, 2] if three else 0.0
    f0, f1, f2 = out[i, 0], out[i, 1], out[i, 2] if three else 0.0
    for s in range(first, stop):
        u = numba.uint64(s)  # unsigned: no test for negative indices
        if a[u] != i:
            out[i, 0], out[i, 1] = f0, f1
            if three:
                out[i, 2] = f2
            i = a[u]
            y0, y1, y2 = x[i, 0], x[i, 1], x[i, 2] if three else 0.0
            f0, f1, f2 = out[i, 0], out[i, 1], out[i, 2] if three else 0.0
        j = b[u]
        d = (y0 - x[j, 0], y1 - x[j, 1], y2 - x[j, 2] if three else 0.0)
        if c[u] != 0.0:  # the velocities are read only for a dashpot
            w = (v[i, 0] - v[j, 0], v[i, 1] - v[j, 1], v[i, 2] - v[j, 2] if three else 0.0)
            length, _, rate, scale = spring_state(k[u], rest[u], c[u], d, w)
            power += dashpot_power(c[u], rate)
        else:
            length, _, _, scale = spring_state(k[u], rest[u], 0.0, d)
        if length > peak[0] * rest[u]:  # cheaper than dividing for every spring
            peak[0] = length / rest[u]
        g0, g1, g2 = scale * d[0], scale * d[1], scale * d[2]
        f0 += g0
        out[j, 0] -= g0
        f1 += g1
        out[j, 1] -= g1
        if three:
            f2 += g2
            out[j, 2] -= g2
    out[i, 0], out[i, 1] = f0, f1
    if three:
        out[i, 2] = f2
    return peak[0], power


@numba.njit(cache=True, inline="always")
def _add_spring_block(x, v, a, b, k, rest, c, first, stop, out):
    """`_add_spring_forces` compiled apart for 2-D and 3-D (``three`` a constant in each)."""
    if x.shape[1] == 3:
        return _add_spring_forces(x, v, a, b, k, rest, c, first, stop, out, True)
    return _add_spring_forces(x, v, a, b, k, rest, c, first, stop, out, False)


@numba.njit(cache=True)
def spring_forces_serial(x, v, a, b, k, rest, c, out):
    """One thread: add every spring's force to ``out``; return (largest stretch, dashpot power)."""
    return _add_spring_block(x, v, a, b, k, rest, c, 0, len(a), out)


@numba.njit(cache=True, parallel=True)
def spring_forces_parallel(x, v, a, b, k, rest, c, partial, out, reduce):
    """Threads: spring block 0 is summed into ``out``, block t > 0 into ``partial[t - 1]``.

    With ``reduce`` the partial buffers are then added to ``out`` particle by
    particle; else ``out`` is cleared first (the thread of block 0 does it while
    the others clear theirs) and the caller adds them in its own loop (see
    `compile_advance`).
    """
    blocks = len(partial) + 1
    count = len(a)
    stretches = np.zeros(blocks)
    powers = np.zeros(blocks)
    for t in numba.prange(blocks):
        first, stop = t * count // blocks, (t + 1) * count // blocks
        if t == 0:
            if not reduce:
                out[:] = 0.0
            sums = _add_spring_block(x, v, a, b, k, rest, c, first, stop, out)
        else:
            partial[t - 1] = 0.0
            sums = _add_spring_block(x, v, a, b, k, rest, c, first, stop, partial[t - 1])
        stretches[t], powers[t] = sums
    n, dim = out.shape
    for i in numba.prange(n if reduce else 0):
        for q in range(dim):
            total = out[i, q]
            for t in range(blocks - 1):
                total += partial[t, i, q]
            out[i, q] = total
    return stretches.max(), powers.sum()


def _compile_energy(parallel: bool):
    """`elastic_energy` compiled for threads (``parallel``) or for one thread."""
    loop = numba.prange if parallel else range

    @numba.njit(cache=True, parallel=parallel)
    def elastic_energy(x, a, b, k, rest, blocks):
        """Σ ½ k (|d| - l)² over all springs (J), summed in ``blocks`` blocks, then in order."""
        count = len(a)
        energies = np.zeros(blocks)
        for t in loop(blocks):
            energy = 0.0
            for s in range(t * count // blocks, (t + 1) * count // blocks):
                length = spring_state(k[s], rest[s], 0.0, separation(x, a[s], b[s]))[0]
                energy += spring_energy(k[s], rest[s], length)
            energies[t] = energy
        return energies.sum()

    return elastic_energy


elastic_energy_serial, elastic_energy_parallel = _compile_energy(False), _compile_energy(True)


@numba.njit(cache=True)
def jacobian_blocks(x, a, b, k, rest, c, stiff, damp):
    """Each spring's blocks (E, d, d) of `equations.spring_jacobian`, B into ``stiff`` and, if
    it is not empty, C into ``damp``."""
    dim = x.shape[1]
    for s in range(len(a)):
        d = separation(x, a[s], b[s])
        length, safe, _, _ = spring_state(k[s], rest[s], 0.0, d)
        n = (d[0] / safe, d[1] / safe, d[2] / safe)  # 0 for coincident ends: B = k I
        across = transverse_stiffness(k[s], rest[s], length, safe)
        for i in range(dim):
            for j in range(dim):
                same = 1.0 if i == j else 0.0
                stiff[s, i, j], damping = spring_jacobian(k[s], across, c[s], n[i], n[j], same)
                if len(damp):
                    damp[s, i, j] = damping


# Sums over the state at the end of a step: one pass each, no temporary arrays, the same
# quantities as the numpy kernel's (`backends.numpy.finite`, `equations.damping_work`). The work
# is summed over blocks of `BLOCK` particles, then over the blocks in order, so one thread
# and several give the same sum; it may differ from numpy's in the last bits.


@numba.njit(cache=True, parallel=True, fastmath={"reassoc"})
def finite(x, v):
    """Whether every coordinate of positions ``x`` and velocities ``v`` (N, d) is finite:
    0·u is 0 for a finite u and NaN for an infinite or NaN one, and a sum of them is 0
    in any order, so the loop may add them on vector registers, and for a big state
    (`PARALLEL_MIN_PARTICLES`) on the threads. One loop reads both arrays: two streams at
    once read memory faster than one after the other."""
    xs, vs = x.ravel(), v.ravel()
    if len(xs) != len(vs):  # the loop reads both up to len(xs), unchecked
        raise ValueError("positions and velocities must have the same shape")
    zero = 0.0
    if len(x) < _REDUCTIONS_MIN_PARTICLES:
        for i in range(len(xs)):
            zero += 0.0 * xs[i] + 0.0 * vs[i]
    else:
        for i in numba.prange(len(xs)):
            zero += 0.0 * xs[i] + 0.0 * vs[i]
    return zero == 0.0


@numba.njit(cache=True)
def _kick_works(masses, v_before, v_after, factor, block):
    """Σ `equations.damping_kick_work` (J) of the kicks (factor - 1)·v_before over the
    particles of ``block``."""
    total = 0.0
    for i in range(block * BLOCK, min(len(masses), (block + 1) * BLOCK)):
        for q in range(v_before.shape[1]):
            total += damping_kick_work(masses[i], factor, v_before[i, q], v_after[i, q])
    return total


@numba.njit(cache=True, parallel=True)
def damping_work(masses, v_before, v_after, factor):
    """`equations.damping_work` (J): minus the work of the kicks (factor - 1)·v_before.

    Summed by blocks of `BLOCK` particles, on the threads for a big state
    (`PARALLEL_MIN_PARTICLES`), then over the blocks in order: the same sum either way.
    """
    sums = np.empty((len(masses) + BLOCK - 1) // BLOCK)
    if len(masses) < _REDUCTIONS_MIN_PARTICLES:
        for block in range(len(sums)):
            sums[block] = _kick_works(masses, v_before, v_after, factor, block)
    else:
        for block in numba.prange(len(sums)):
            sums[block] = _kick_works(masses, v_before, v_after, factor, block)
    total = 0.0
    for block in range(len(sums)):
        total += sums[block]
    return -total


# The ground's clamp in one loop over the particles, with its booking on the way. The
# numpy backend's `backends.numpy.ground_clamp` takes some thirty numpy calls on the few particles
# below the plane, which for a small body cost more than its springs; this loop applies
# the same `equations.ground_contact` per particle (put back on the plane, its new velocity
# and the energy removed).


@numba.njit(cache=True)
def ground_clamp(x, v, x_old, v_old, masses, fixed, normal, height, dt, friction):
    """Clamp the free particles with x·n < ``height`` onto the plane, in place; return the
    energy (J) the ground removed (`backends.numpy.ground_clamp`, one particle at a time)."""
    keep = 1.0 - friction
    removed = 0.0
    dim = x.shape[1]
    n = (normal[0], normal[1], normal[2] if dim == 3 else 0.0)
    for i in range(len(x)):
        above = 0.0
        for q in range(dim):
            above += x[i, q] * normal[q]
        if not above < height or fixed[i]:
            continue
        put, speed, lost = ground_contact(
            masses[i],
            row(x, i),
            above,
            row(v, i),
            row(x_old, i),
            row(v_old, i),
            n,
            height,
            dt,
            keep,
        )
        removed += lost
        for q in range(dim):
            x[i, q] = put[q]
            v[i, q] = speed[q]
    return removed


@numba.njit(cache=True, inline="always")
def row(x, i):
    """Row i of ``x`` (N, d) as three coordinates, the third 0 in 2-D."""
    return x[i, 0], x[i, 1], x[i, 2] if x.shape[1] == 3 else 0.0


# The update loop: `compile_advance` turns an update such as `integrators.Verlet.update`
# into a loop that computes a = F/m (plus gravity's g) and the update together, and adds
# the spring forces the spring loops left pending in the same pass. The update is handed to
# numba as it is written (`register_jitable`), and the loop calls it as a closure variable:
# numba inlines it, and keys the loop's disk cache by the update's own code, so msdlab's
# integrators' loops are compiled once per machine; a user's update is compiled once per
# process. `advance_particles` keeps one loop per update for the process and runs it, or
# runs the update on whole arrays if numba cannot compile it.

# One compiled loop per update function, threaded or not, for the whole process; None for
# an update numba cannot compile (it runs on arrays).
_LOOPS: dict[tuple[Callable, bool], Callable | None] = {}


@numba.njit(cache=True, inline="always")
def particle_acceleration(i, q, forces, partial, field, masses, fixed):
    """a = (F + m·g)/m (m/s²) of particle i along q, 0 if fixed. F is ``forces`` (N, d)
    plus the threads' ``partial`` forces (T, N, d; T = 0 if none), added in the order
    the edge loop adds them (see `spring_forces_parallel`)."""
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
    layout: Layout,
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
        x_new, v_new = np.empty_like(x), np.empty_like(v)
        arrays = (x, v, forces, partial, field, layout.masses, layout.fixed)
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
    masses, free = layout.masses[:, None], ~layout.fixed[:, None]
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


class NumbaKernel:
    """The numba backend (`contract.SpringKernel`), with what it derives from a body's
    `Layout` kept until it is given a new one (the body was edited).

    A lattice (`lattice.LatticeSprings`, the springs of `Body.grid`) is gathered by offset
    (`lattice.gather`, laid out by `lattice.plan`); an edge list goes through the edge
    loop, over the springs sorted by their ends (`sorted_edges`), with one force buffer
    per extra thread. ``springs`` (indices) restricts a computation to some springs, on
    one thread, in the body's order.
    """

    name = "numba"
    finite = staticmethod(finite)
    damping_work = staticmethod(damping_work)
    ground_clamp = staticmethod(ground_clamp)

    def __init__(self) -> None:
        self._layout: Layout | None = None  # the layout the next two were derived from
        self._sorted: tuple[np.ndarray, ...] = ()  # an edge list's springs, `sorted_edges`
        self._gather = NO_PLAN  # a lattice's, see `lattice.plan`
        self._forces = np.zeros((0, 0))  # the spring forces of `advance`
        self._partial = np.zeros((0, 0, 0))  # the edge loop's extra threads' forces
        self._none = np.zeros((0, 0, 0))  # no threads' forces

    def spring_forces(
        self,
        layout: Layout,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> SpringSums:
        """Add the spring and dashpot forces (N) to ``out`` (N, d); the largest stretch
        |d|/l and the power (W) the dashpots take come from the same loop."""
        if springs is not None:
            a, b, k, rest, c = (array[springs] for array in layout.edges.arrays())
            return SpringSums(*spring_forces_serial(x, v, a, b, k, rest, c, out))
        return SpringSums(*self._pass(layout, x, v, out, fused=False)[:2])

    def elastic_energy(
        self, layout: Layout, x: np.ndarray, springs: np.ndarray | None = None
    ) -> float:
        """Energy (J) stored in the springs (or in the given ones) at positions x; a
        lattice's summed by offset (`lattice.grid_sum`)."""
        lattice = layout.lattice
        if springs is None and lattice is not None:
            parallel = lattice.count >= PARALLEL_MIN_SPRINGS and numba.get_num_threads() > 1
            grid_sum = grid_sum_parallel if parallel else grid_sum_serial
            return grid_sum(x, *padded_shape(lattice), lattice.stiffness, lattice.rest_lengths)
        edges = layout.edges
        arrays = (edges.a, edges.b, edges.stiffness, edges.rest_lengths)
        if springs is not None:
            return elastic_energy_serial(x, *(array[springs] for array in arrays), 1)
        blocks = numba.get_num_threads() if edges.count >= PARALLEL_MIN_SPRINGS else 1
        energy = elastic_energy_parallel if blocks > 1 else elastic_energy_serial
        return energy(x, *arrays, blocks)

    def jacobians(self, layout: Layout, x: np.ndarray) -> Jacobians:
        """∂F/∂x and ∂F/∂v of the springs on the layout's pattern, as `backends.numpy.jacobians`,
        with the blocks computed spring by spring."""
        edges = layout.edges
        dim = x.shape[1]
        stiff = np.empty((edges.count, dim, dim))
        damp = np.empty((edges.count if edges.damping.any() else 0, dim, dim))
        jacobian_blocks(x, *edges.arrays(), stiff, damp)
        return Jacobians(*layout.pattern.jacobians(stiff, damp if len(damp) else None))

    def advance(
        self,
        update: Callable,
        layout: Layout,
        x: np.ndarray,
        v: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        forces: np.ndarray | None = None,
    ) -> Advanced:
        """``update(x, v, a, dt, *coefficients)`` with a = (F + m·g)/m (0 if fixed), F the
        spring forces plus ``forces`` (N, d) if given, g = ``field`` (d,) in m/s²: the
        springs' loop, then one loop doing a and the update (`advance_particles`).

        The spring forces not yet added up (the threads' buffers, or the gather's forces
        by coordinate) are added in the update's loop, not in a pass of their own; the
        other ``forces`` are added there after the springs'.
        """
        if self._forces.shape != x.shape:
            self._forces = np.empty_like(x)
        if forces is None:
            stretch, power, total, partial = self._pass(layout, x, v, self._forces, fused=True)
        else:
            self._forces.fill(0.0)
            stretch, power, _, _ = self._pass(layout, x, v, self._forces, fused=False)
            total, partial = self._forces, forces[np.newaxis]
        parallel = len(x) >= PARALLEL_MIN_PARTICLES and numba.get_num_threads() > 1
        state = (update, layout, x, v, total, partial, field, dt, coefficients)
        return Advanced(*advance_particles(*state, parallel), stretch, power)

    def _pass(
        self, layout: Layout, x: np.ndarray, v: np.ndarray, out: np.ndarray, fused: bool
    ) -> tuple[float, float, np.ndarray, np.ndarray]:
        """The springs' loop: the largest stretch, the dashpot power (W), and the spring
        forces as an (N, d) array plus the threads' (T, N, d) to add to it.

        Not ``fused``, the forces are added to ``out`` and no threads' are left. ``fused``,
        ``out`` is scratch, and the last sum is left to the caller's loop: the forces are
        ``out`` (cleared first) plus the edge loop's threads' buffers, or the gather's
        forces by coordinate, seen transposed.
        """
        if layout is not self._layout:
            self._lay_out(layout, x)
        if self._gather.lattice is not None:
            kept = self._gather
            parallel = kept.springs >= PARALLEL_MIN_GATHERED and numba.get_num_threads() > 1
            gather = gather_parallel if parallel else gather_serial
            stretch, power = gather(x, v, out, not fused, *kept.arguments)
            return stretch, power, kept.forces if fused else out, self._none
        arrays = self._sorted
        blocks = numba.get_num_threads() if len(arrays[0]) >= PARALLEL_MIN_SPRINGS else 1
        if blocks == 1:
            if fused:
                out.fill(0.0)
            return *spring_forces_serial(x, v, *arrays, out), out, self._none
        if self._partial.shape != (blocks - 1, *x.shape):
            self._partial = np.empty((blocks - 1, *x.shape))
        sums = spring_forces_parallel(x, v, *arrays, self._partial, out, not fused)
        return *sums, out, self._partial if fused else self._none

    def _lay_out(self, layout: Layout, x: np.ndarray) -> None:
        """Derive from a new ``layout`` what the springs' loop reads: a lattice's gather plan
        or an edge list's sorted springs (`sorted_edges`)."""
        self._layout, self._none = layout, np.zeros((0, *x.shape))
        if layout.lattice is not None:
            self._gather = plan(layout.lattice, layout.version, layout.n_particles)
            self._sorted = ()
        else:
            self._gather, self._sorted = NO_PLAN, sorted_edges(layout.edges, layout.n_particles)


def sorted_edges(edges: EdgeSprings, n_particles: int) -> tuple[np.ndarray, ...]:
    """Ends a, b of all springs sorted by (a, b), and the stiffness, rest length and dashpot
    of each, in that order.

    In that order consecutive springs share or neighbour their particles, so the edge loop
    reads and writes memory it has just used, whatever order the springs were added in (a
    shuffled 60³ grid: several times faster). The ends are uint32 (half the memory traffic
    of int64); the values are the body's own arrays, or copies in the sorted order.
    """
    order = np.lexsort((edges.b, edges.a))
    if np.array_equal(order, np.arange(len(order))):
        order = slice(None)
    a, b, *values = (array[order] for array in edges.arrays())
    index = np.uint32 if n_particles < 2**32 else np.uint64
    return (a.astype(index), b.astype(index), *values)
