"""The numba spring kernel: the same `msdlab.equations`, compiled into loops over the springs.

`kernels.NumpyKernel` applies the equations to (E, d) arrays of all springs,
then sums them per particle. `NumbaKernel` compiles the same functions of
`msdlab.equations` and applies them to the springs one by one: for each it
computes the length, the force along it (eq. 1.2 plus the dashpot), adds it to
particle a and its opposite to particle b (eq. 1.1), and keeps the largest
stretch |d|/l and the dashpot power on the way, with no temporary arrays.
Large bodies split the springs between the threads, each summing into its own
force buffer (no two threads write the same memory; the first one writes the
result), and the buffers are then added per particle. The springs are visited
sorted by their ends, so memory is read in order whatever order they were
added in; along the springs of one first end, its position and force stay in
registers. Their stiffness, rest length and dashpot come from a small table
of the distinct triples, through a one- or two-byte class per spring.

Grid bodies (`msdlab.stencil`) whose springs share their values per offset
go by offset instead, with no list of springs: each particle computes its
springs to the neighbours ahead of it (half the stencil, so each spring
once, with the same `equations.spring_force`), adds their forces to itself
and, in a second loop, their opposites to the neighbours. The positions are
copied by coordinate so that the inner loops walk contiguous memory on
vector registers, over whole grid rows (those whose neighbour would leave
its row masked out), three offsets at a time (a particle's position is read
and its force written once for three springs). The threads take grid
planes, every third one at once in three rounds, so that no two write the
same particle; one thread takes them in the same order, with the same sums.

`NumbaKernel.advance` compiles an integrator's update function (for example
`integrators.verlet_update`) into one loop over the particles that computes
a = F/m (plus gravity's g) and the update together; it is compiled once per
process and update. When the springs' forces are all the forces
(`NumbaKernel.advance_with_springs`), the spring forces not yet summed (the
edge loop's threads' buffers, or the gather's forces by coordinate) are added
in that loop too, not in a pass of their own.

The spring loops are compiled on first use and cached on disk (``cache=True``),
so compiling is paid once per machine and numba version. Set the number of
threads with ``NUMBA_NUM_THREADS`` or `numba.set_num_threads`.
"""

from __future__ import annotations

import math
import sys
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING

import numba
import numpy as np
import scipy.sparse as sp

from . import equations
from .body import Body
from .stencil import GridStencil, grid_stencil

if TYPE_CHECKING:
    from .kernels import JacobianPattern, StepEnd

# Below this many springs (particles for the update) one thread is faster than waking the others.
PARALLEL_MIN_SPRINGS = 50_000
PARALLEL_MIN_PARTICLES = 20_000
# The gather wakes the threads four times a step: it waits for more springs (about 28³ grid).
PARALLEL_MIN_GATHERED = 250_000
# Particles a gather block holds (whole grid rows): long inner loops, enough blocks for threads.
GATHER_BLOCK = 4096
# At most this many distinct (stiffness, rest length, dashpot) triples are kept as a table
# with a class number per spring (uint8 up to 256, else uint16); past it, the values per spring.
SPRING_CLASSES = 65_536
# Odd constants that mix the bits of the spring values into a hash (see `_spring_classes`).
_MIX = (np.uint64(0x9E3779B97F4A7C15), np.uint64(0xC2B2AE3D27D4EB4F), np.uint64(0x165667B19E3779F9))

_spring_force = numba.njit(cache=True, inline="always")(equations.spring_force)
_spring_energy = numba.njit(cache=True, inline="always")(equations.spring_energy)
_dashpot_power_of = numba.njit(cache=True, inline="always")(equations.dashpot_power)
_transverse_stiffness = numba.njit(cache=True, inline="always")(equations.transverse_stiffness)
_inverse_mass = numba.njit(cache=True, inline="always")(equations.inverse_mass)
_acceleration = numba.njit(cache=True, inline="always")(equations.acceleration)


@numba.njit(cache=True, inline="always")
def _add_spring_forces(x, v, a, b, kinds, k, rest, c, first, stop, out, three):
    """Add the forces of springs ``first`` to ``stop - 1`` to ``out``, (N, 3) if ``three``
    else (N, 2). Returns the largest stretch |d|/l and the dashpot power (W) of those springs.

    Spring s has the stiffness, rest length and dashpot ``k``, ``rest``, ``c`` at
    ``kinds[s]`` (see `_spring_classes`), or at s when ``kinds`` is None. Along a
    run of springs with the same end a, a's position and force stay in registers:
    its force is summed in the same order as in memory, so the sums do not change.
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
        m = u if kinds is None else kinds[u]
        d0 = y0 - x[j, 0]
        d1 = y1 - x[j, 1]
        d2 = y2 - x[j, 2] if three else 0.0
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if length > peak[0] * rest[m]:  # cheaper than dividing for every spring
            peak[0] = length / rest[m]
        if length == 0.0:  # coincident ends: no direction, no force
            continue
        rate = 0.0
        if c[m] != 0.0:
            closing = (v[i, 0] - v[j, 0]) * d0 + (v[i, 1] - v[j, 1]) * d1
            if three:
                closing += (v[i, 2] - v[j, 2]) * d2
            rate = closing / length
            power += _dashpot_power_of(c[m], rate)
        scale = _spring_force(k[m], rest[m], length, c[m], rate) / length
        f0 += scale * d0
        out[j, 0] -= scale * d0
        f1 += scale * d1
        out[j, 1] -= scale * d1
        if three:
            f2 += scale * d2
            out[j, 2] -= scale * d2
    out[i, 0], out[i, 1] = f0, f1
    if three:
        out[i, 2] = f2
    return peak[0], power


@numba.njit(cache=True, inline="always")
def _add_spring_block(x, v, a, b, kinds, k, rest, c, first, stop, out):
    """`_add_spring_forces` compiled apart for 2-D and 3-D (``three`` a constant in each)."""
    if x.shape[1] == 3:
        return _add_spring_forces(x, v, a, b, kinds, k, rest, c, first, stop, out, True)
    return _add_spring_forces(x, v, a, b, kinds, k, rest, c, first, stop, out, False)


@numba.njit(cache=True)
def _spring_forces_serial(x, v, a, b, kinds, k, rest, c, out):
    """One thread: add every spring's force to ``out``; return (largest stretch, dashpot power)."""
    return _add_spring_block(x, v, a, b, kinds, k, rest, c, 0, len(a), out)


@numba.njit(cache=True, parallel=True)
def _spring_forces_parallel(x, v, a, b, kinds, k, rest, c, partial, out, reduce):
    """Threads: spring block 0 is summed into ``out``, block t > 0 into ``partial[t - 1]``.

    With ``reduce`` the partial buffers are then added to ``out`` particle by
    particle; else ``out`` is cleared first (the thread of block 0 does it while
    the others clear theirs) and the caller adds them in its own loop (see
    `_compile_advance`).
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
            sums = _add_spring_block(x, v, a, b, kinds, k, rest, c, first, stop, out)
        else:
            partial[t - 1] = 0.0
            sums = _add_spring_block(x, v, a, b, kinds, k, rest, c, first, stop, partial[t - 1])
        stretches[t], powers[t] = sums
    n, dim = out.shape
    for i in numba.prange(n if reduce else 0):
        for q in range(dim):
            total = out[i, q]
            for t in range(blocks - 1):
                total += partial[t, i, q]
            out[i, q] = total
    return stretches.max(), powers.sum()


@numba.njit(cache=True)
def _spring_classes(k_bits, rest_bits, c_bits, slots, kinds, table):
    """Number the distinct (stiffness, rest length, dashpot) triples of the springs, in one pass.

    Spring s gets in ``kinds[s]`` the class of its triple, whose bit patterns
    (int64 views of the values, so equal means identical) go to ``table[class]``.
    ``slots`` (a power of two long, zero) is the hash table of the classes
    (class + 1, 0 for free). Returns the number of classes, or -1 if there
    are more than ``len(table)``.
    """
    mask = numba.uint64(len(slots) - 1)
    count = 0
    for s in range(len(kinds)):
        key = (k_bits[s], rest_bits[s], c_bits[s])
        h = numba.uint64(key[0]) * _MIX[0] ^ numba.uint64(key[1]) * _MIX[1]
        h ^= numba.uint64(key[2]) * _MIX[2]
        slot = (h ^ (h >> numba.uint64(32))) & mask
        while slots[slot] != 0 and (
            table[slots[slot] - 1, 0] != key[0]
            or table[slots[slot] - 1, 1] != key[1]
            or table[slots[slot] - 1, 2] != key[2]
        ):
            slot = (slot + numba.uint64(1)) & mask
        if slots[slot] == 0:
            if count == len(table):
                return -1
            table[count, 0], table[count, 1], table[count, 2] = key
            count += 1
            slots[slot] = count
        kinds[s] = slots[slot] - 1
    return count


@numba.njit(cache=True, error_model="numpy")
def _pull(y0, y1, y2, x0, x1, x2, q, there, k, rest):
    """The spring from a particle at y to particle ``q``, times ``there`` (1, or 0 when
    that neighbour does not exist): f/|d| of eq. (1.2) (N/m), d = y - x_q (3 components)
    and |d|² (m²). The force on the particle is (f/|d|)·d, on ``q`` its opposite.
    """
    d0, d1, d2 = y0 - x0[q], y1 - x1[q], y2 - x2[q]
    length_squared = d0 * d0 + d1 * d1 + d2 * d2
    length = math.sqrt(length_squared)
    safe = length if length > 0.0 else 1.0  # coincident ends: no direction, no force
    scale = there * _spring_force(k, rest, safe, 0.0, 0.0) / safe
    scale = scale if length > 0.0 else 0.0
    return scale, d0, d1, d2, there * length_squared


@numba.njit(cache=True, error_model="numpy")
def _pull_damped(y0, y1, y2, u0, u1, u2, xs, vs, q, there, k, rest, c):
    """`_pull` with the dashpot c (N·s/m) on velocities u and vs; also returns its power (W)."""
    x0, x1, x2 = xs
    v0, v1, v2 = vs
    d0, d1, d2 = y0 - x0[q], y1 - x1[q], y2 - x2[q]
    length_squared = d0 * d0 + d1 * d1 + d2 * d2
    length = math.sqrt(length_squared)
    safe = length if length > 0.0 else 1.0
    rate = ((u0 - v0[q]) * d0 + (u1 - v1[q]) * d1 + (u2 - v2[q]) * d2) / safe
    power = there * _dashpot_power_of(c, rate)
    scale = there * _spring_force(k, rest, safe, c, rate) / safe
    scale = scale if length > 0.0 else 0.0
    return scale, d0, d1, d2, there * length_squared, power


@numba.njit(cache=True, error_model="numpy")
def _push_three(xs, vs, fs, squared, columns, masks, first, stop, shifts, values, scales, pad):
    """Add to particles ``first`` to ``stop - 1`` the forces of their springs to three
    neighbours, at p + ``shifts[j]``, the same grid row offset apart, and keep each
    spring's f/|d| in ``scales[j, pad + p - first]`` for `_react`.

    ``xs``, ``vs``, ``fs`` are positions, velocities and forces by coordinate,
    contiguous, so the loop runs on vector registers; a particle's position
    is read and its force written once for three springs. ``columns[masks[j], p - first]``
    is 1 where p has neighbour j, 0 where it would leave p's grid row.
    ``values[j]`` (3, 4) holds the spring's stiffness, rest length, dashpot and
    1/rest²; ``squared[p]`` keeps the largest |d|²/l² seen (a running maximum
    would keep the loop scalar). Returns the dashpot power (W) of these
    springs; with dashpots the loop stays scalar. Indices are unsigned: numba
    then needs no negative-index test, which would also keep the loop scalar.
    """
    x0, x1, x2 = xs
    f0, f1, f2 = fs
    ma, mb, mc = masks  # rows of `columns`
    sa, sb, sc = shifts
    ka, ra, ca, wa = values[0, 0], values[0, 1], values[0, 2], values[0, 3]
    kb, rb, cb, wb = values[1, 0], values[1, 1], values[1, 2], values[1, 3]
    kc, rc, cc, wc = values[2, 0], values[2, 1], values[2, 2], values[2, 3]
    kept_a, kept_b, kept_c = scales[0], scales[1], scales[2]
    power = 0.0
    if ca == 0.0 and cb == 0.0 and cc == 0.0:  # no sum across springs: vector registers
        for i in range(first, stop):
            p, r = numba.uint64(i), numba.uint64(i - first)
            y0, y1, y2 = x0[p], x1[p], x2[p]
            qa, qb, qc = numba.uint64(i + sa), numba.uint64(i + sb), numba.uint64(i + sc)
            a, a0, a1, a2, la = _pull(y0, y1, y2, x0, x1, x2, qa, columns[ma, r], ka, ra)
            b, b0, b1, b2, lb = _pull(y0, y1, y2, x0, x1, x2, qb, columns[mb, r], kb, rb)
            c, c0, c1, c2, lc = _pull(y0, y1, y2, x0, x1, x2, qc, columns[mc, r], kc, rc)
            f0[p] += a * a0 + b * b0 + c * c0
            f1[p] += a * a1 + b * b1 + c * c1
            f2[p] += a * a2 + b * b2 + c * c2
            kept = numba.uint64(i - first + pad)
            kept_a[kept], kept_b[kept], kept_c[kept] = a, b, c
            squared[p] = max(squared[p], la * wa, lb * wb, lc * wc)
        return power
    v0, v1, v2 = vs
    for i in range(first, stop):
        p, r = numba.uint64(i), numba.uint64(i - first)
        y0, y1, y2, u0, u1, u2 = x0[p], x1[p], x2[p], v0[p], v1[p], v2[p]
        y, u = (y0, y1, y2), (u0, u1, u2)
        qa, qb, qc = numba.uint64(i + sa), numba.uint64(i + sb), numba.uint64(i + sc)
        a, a0, a1, a2, la, pa = _pull_damped(*y, *u, xs, vs, qa, columns[ma, r], ka, ra, ca)
        b, b0, b1, b2, lb, pb = _pull_damped(*y, *u, xs, vs, qb, columns[mb, r], kb, rb, cb)
        c, c0, c1, c2, lc, pc = _pull_damped(*y, *u, xs, vs, qc, columns[mc, r], kc, rc, cc)
        f0[p] += a * a0 + b * b0 + c * c0
        f1[p] += a * a1 + b * b1 + c * c1
        f2[p] += a * a2 + b * b2 + c * c2
        kept = numba.uint64(i - first + pad)
        kept_a[kept], kept_b[kept], kept_c[kept] = a, b, c
        squared[p] = max(squared[p], la * wa, lb * wb, lc * wc)
        power += pa + pb + pc
    return power


@numba.njit(cache=True, error_model="numpy")
def _react(xs, fs, scales, first, stop, shifts, pad):
    """Add to each neighbour q = p + ``shifts[j]`` of particles p = ``first`` to ``stop - 1``
    the opposite of the force its spring exerts on p (eq. 1.1), -(f/|d|)·(x_p - x_q),
    with f/|d| from ``scales[j, pad + p - first]`` (see `_push_three`).

    One loop over the neighbours q takes the three springs, so q's position is
    read and its force written once. ``scales`` is 0 in its first and last
    ``pad`` columns (pad ≥ the spread of the shifts), where q has no spring j;
    the scratch padding is as wide, so p stays in memory there.
    """
    x0, x1, x2 = xs
    f0, f1, f2 = fs
    kept_a, kept_b, kept_c = scales[0], scales[1], scales[2]
    sa, sb, sc = shifts
    low, high = min(sa, sb, sc), max(sa, sb, sc)
    scales[:, pad + stop - first :] = 0.0
    for i in range(first + low, stop + high):
        q = numba.uint64(i)
        pa, pb, pc = numba.uint64(i - sa), numba.uint64(i - sb), numba.uint64(i - sc)
        a = kept_a[numba.uint64(i - sa - first + pad)]
        b = kept_b[numba.uint64(i - sb - first + pad)]
        c = kept_c[numba.uint64(i - sc - first + pad)]
        y0, y1, y2 = x0[q], x1[q], x2[q]
        f0[q] -= a * (x0[pa] - y0) + b * (x0[pb] - y0) + c * (x0[pc] - y0)
        f1[q] -= a * (x1[pa] - y1) + b * (x1[pb] - y1) + c * (x1[pc] - y1)
        f2[q] -= a * (x2[pa] - y2) + b * (x2[pb] - y2) + c * (x2[pc] - y2)


@numba.njit(cache=True, error_model="numpy")
def _push_rows(scratch, pad, columns, shape, triples, rows_of, o2s, values, plane, rows, scales):
    """Add the forces of the springs from the particles of grid rows ``rows`` (first, stop)
    of ``plane`` to their neighbours ahead to both ends; return their dashpot power (W).

    ``scratch`` (10, N + 2·pad) holds the positions, velocities and forces by
    coordinate and the squared stretches, particle p at p + pad (the padding
    stays zero, so a masked neighbour past either end is still in memory);
    ``scales`` (3, rows·n_2 + 2·pad) is the room `_push_three` and `_react` share.
    Triple t joins each particle to its neighbours at the offsets
    (``triples[t]``, ``o2s[t, j]``), j = 0, 1, 2, with the spring values
    ``values[t, j]`` (see `_stencil_triples`); for each, the rows whose
    neighbours exist are consecutive, so the inner loops run over all of them
    at once, and ``columns[rows_of[t, j]]`` masks the particles whose
    neighbour would be past the end of their row (see `_column_masks`).
    """
    xs = (scratch[0], scratch[1], scratch[2])
    vs = (scratch[3], scratch[4], scratch[5])
    fs = (scratch[6], scratch[7], scratch[8])
    n0, n1, n2 = shape[0], shape[1], shape[2]
    power = 0.0
    for t in range(len(triples)):
        o0, o1 = triples[t, 0], triples[t, 1]
        lo, hi = max(rows[0], -o1), min(rows[1], n1 - o1)  # rows whose neighbours exist
        if not (0 <= plane + o0 < n0 and lo < hi):
            continue
        shift = (o0 * n1 + o1) * n2
        first, stop = (plane * n1 + lo) * n2 + pad, (plane * n1 + hi) * n2 + pad
        masks = (rows_of[t, 0], rows_of[t, 1], rows_of[t, 2])
        shifts = (shift + o2s[t, 0], shift + o2s[t, 1], shift + o2s[t, 2])
        power += _push_three(
            xs, vs, fs, scratch[9], columns, masks, first, stop, shifts, values[t], scales, pad
        )
        _react(xs, fs, scales, first, stop, shifts, pad)
    return power


@numba.njit(cache=True, error_model="numpy")
def _push_unit(scratch, pad, columns, shape, rows, triples, rows_of, o2s, values, unit):
    """`_push_rows` for a unit of work: grid plane ``unit`` (3-D), or rows ``unit``·rows
    to (``unit`` + 1)·rows - 1 (2-D), ``rows`` at a time. Returns the largest squared
    stretch |d|²/l² of the springs from its particles and their dashpot power (W).

    A unit's springs reach the next unit only, and its masked neighbours (whose
    force is 0) the one after; so units three apart can be pushed at once.
    """
    n0, n1, n2 = shape[0], shape[1], shape[2]
    plane, lo, hi = (unit, 0, n1) if n0 > 1 else (0, unit * rows, min(unit * rows + rows, n1))
    scales = np.zeros((3, rows * n2 + 2 * pad))
    power = 0.0
    for first in range(lo, hi, rows):
        block = (first, min(first + rows, hi))
        power += _push_rows(
            scratch, pad, columns, shape, triples, rows_of, o2s, values, plane, block, scales
        )
    start, end = (plane * n1 + lo) * n2 + pad, (plane * n1 + hi) * n2 + pad
    return scratch[9, start:end].max(), power


@numba.njit(cache=True, error_model="numpy")
def _gather_serial(x, v, shape, triples, rows_of, o2s, values, columns, rows, scratch, out, add):
    """One thread: `_gather_parallel`'s work in the same order, so the same sums."""
    pad = (scratch.shape[1] - len(x)) // 2
    damped = np.any(values[:, :, 2] != 0.0)
    scratch[6:, :] = 0.0
    for q in range(x.shape[1]):
        scratch[q, pad : pad + len(x)] = x[:, q]
        if damped:
            scratch[3 + q, pad : pad + len(x)] = v[:, q]
    units = shape[0] if shape[0] > 1 else (shape[1] + rows - 1) // rows
    squares = np.zeros(units)
    powers = np.zeros(units)
    for phase in range(3):
        for unit in range(phase, units, 3):
            squares[unit], powers[unit] = _push_unit(
                scratch, pad, columns, shape, rows, triples, rows_of, o2s, values, unit
            )
    for q in range(x.shape[1] if add else 0):
        out[:, q] += scratch[6 + q, pad : pad + len(x)]
    return squares, powers


@numba.njit(cache=True, parallel=True, error_model="numpy")
def _gather_parallel(x, v, shape, triples, rows_of, o2s, values, columns, rows, scratch, out, add):
    """Add to ``out`` (N, d) the forces of a grid body's springs, each computed once, from
    the particle behind (`_push_unit`); return each unit's largest squared stretch
    |d|²/l² and dashpot power (W). Without ``add`` the forces stay in ``scratch``
    (rows 6 to 8) for the caller to add in a loop of its own (see `_compile_advance`).

    The threads push every third unit at once, in three rounds, so no two
    write the same particle.
    """
    pad = (scratch.shape[1] - len(x)) // 2
    damped = np.any(values[:, :, 2] != 0.0)
    for p in numba.prange(len(x)):
        for q in range(x.shape[1]):
            scratch[q, p + pad] = x[p, q]
            if damped:
                scratch[3 + q, p + pad] = v[p, q]
        scratch[6, p + pad] = scratch[7, p + pad] = scratch[8, p + pad] = scratch[9, p + pad] = 0.0
    units = shape[0] if shape[0] > 1 else (shape[1] + rows - 1) // rows
    squares = np.zeros(units)
    powers = np.zeros(units)
    for phase in range(3):
        for u in numba.prange((units - phase + 2) // 3):
            unit = phase + 3 * u
            squares[unit], powers[unit] = _push_unit(
                scratch, pad, columns, shape, rows, triples, rows_of, o2s, values, unit
            )
    for p in numba.prange(len(x) if add else 0):
        for q in range(x.shape[1]):
            out[p, q] += scratch[6 + q, p + pad]
    return squares, powers


def _stencil_triples(offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The stencil's offsets, each pointing ahead (o or -o, whichever is later in C order),
    grouped by their first two coordinates, three at a time.

    Returns (triples, members, o2s): triple t joins each particle to those at
    (``triples[t]``, ``o2s[t, j]``), j = 0, 1, 2, by the springs of offset
    block ``members[t, j]``; -1 marks an empty place (no spring).
    """
    groups: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for m, offset in enumerate(offsets.tolist()):
        o0, o1, o2 = offset if tuple(offset) > (0, 0, 0) else [-o for o in offset]
        groups.setdefault((o0, o1), []).append((o2, m))
    triples, members, o2s = [], [], []
    for (o0, o1), group in sorted(groups.items()):
        group.sort()
        group += [(0, -1)] * (-len(group) % 3)
        for first in range(0, len(group), 3):
            triples.append((o0, o1))
            o2s.append([o2 for o2, _ in group[first : first + 3]])
            members.append([m for _, m in group[first : first + 3]])
    return (
        np.array(triples, dtype=np.int64).reshape(-1, 2),
        np.array(members, dtype=np.int64).reshape(-1, 3),
        np.array(o2s, dtype=np.int64).reshape(-1, 3),
    )


def _column_masks(shape: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, int]:
    """Masks of the particles that have a neighbour ``o_2`` columns along their grid row.

    Returns (masks, rows): ``masks[r + o_2]`` (rows · n_2,) is 1 where column
    c + o_2 exists, for a block of ``rows`` rows of the grid, long enough
    (about ``GATHER_BLOCK`` particles) for the loops over a block to cost
    little more than their arithmetic; the last mask, all 0, is for no spring.
    """
    n1, n2 = int(shape[1]), int(shape[2])
    rows = max(1, min(n1, GATHER_BLOCK // n2))
    reach = int(np.abs(offsets[:, 2]).max(initial=0))
    column = np.arange(n2)
    masks = [np.tile((column + o >= 0) & (column + o < n2), rows) for o in range(-reach, reach + 1)]
    return np.array([*masks, np.zeros(rows * n2, dtype=bool)], dtype=float), rows


def _triple_values(values: np.ndarray, members: np.ndarray) -> np.ndarray:
    """Stiffness, rest length, dashpot and 1/rest² (T, 3, 4) of the springs of each triple
    (`_stencil_triples`), from the values (3, M) of each offset block; 0 for no spring."""
    k, rest, c = values[:, members]
    with np.errstate(divide="ignore"):
        table = np.stack([k, rest, c, 1.0 / rest**2], axis=-1)
    table[members < 0] = 0.0
    return table


@numba.njit(cache=True)
def _uniform_blocks(k, rest, c, starts, values):
    """True if every spring block has one stiffness, rest length and dashpot; they go to
    ``values`` (3, M). Stops at the first spring that differs from its block's first."""
    for m in range(len(starts) - 1):
        first = starts[m]
        values[0, m], values[1, m], values[2, m] = k[first], rest[first], c[first]
        same = True
        for s in range(first, starts[m + 1]):
            same &= (k[s] == k[first]) & (rest[s] == rest[first]) & (c[s] == c[first])
        if not same:
            return False
    return True


@numba.njit(cache=True, inline="always")
def _dashpot_power(x, v, a, b, c, first, stop):
    """Power (W) taken by the dashpots of springs ``first`` to ``stop - 1``."""
    power = 0.0
    for s in range(first, stop):
        if c[s] != 0.0:
            i, j = a[s], b[s]
            squared = 0.0
            closing = 0.0
            for q in range(x.shape[1]):
                d = x[i, q] - x[j, q]
                squared += d * d
                closing += (v[i, q] - v[j, q]) * d
            if squared > 0.0:
                power += _dashpot_power_of(c[s], closing / math.sqrt(squared))
    return power


@numba.njit(cache=True)
def _dashpot_power_serial(x, v, a, b, c):
    """One thread: Σ c ((v_a - v_b)·d/|d|)² over all springs (W)."""
    return _dashpot_power(x, v, a, b, c, 0, len(a))


@numba.njit(cache=True, parallel=True)
def _dashpot_power_parallel(x, v, a, b, c, blocks):
    """Threads: Σ c ((v_a - v_b)·d/|d|)² over all springs (W), in ``blocks`` blocks."""
    count = len(a)
    powers = np.zeros(blocks)
    for t in numba.prange(blocks):
        powers[t] = _dashpot_power(x, v, a, b, c, t * count // blocks, (t + 1) * count // blocks)
    return powers.sum()


@numba.njit(cache=True, inline="always")
def _elastic_energy(x, a, b, k, rest, first, stop):
    """Energy (J) stored in springs ``first`` to ``stop - 1``, Σ ½ k (|d| - l)²."""
    energy = 0.0
    for s in range(first, stop):
        i, j = a[s], b[s]
        squared = 0.0
        for q in range(x.shape[1]):
            d = x[i, q] - x[j, q]
            squared += d * d
        energy += _spring_energy(k[s], rest[s], math.sqrt(squared))
    return energy


@numba.njit(cache=True)
def _elastic_energy_serial(x, a, b, k, rest):
    """One thread: Σ ½ k (|d| - l)² over all springs (J)."""
    return _elastic_energy(x, a, b, k, rest, 0, len(a))


@numba.njit(cache=True, parallel=True)
def _elastic_energy_parallel(x, a, b, k, rest, blocks):
    """Threads: Σ ½ k (|d| - l)² over all springs (J), in ``blocks`` blocks."""
    count = len(a)
    energies = np.zeros(blocks)
    for t in numba.prange(blocks):
        first, stop = t * count // blocks, (t + 1) * count // blocks
        energies[t] = _elastic_energy(x, a, b, k, rest, first, stop)
    return energies.sum()


@numba.njit(cache=True)
def _jacobian_blocks(x, a, b, k, rest, c, stiff, damp):
    """Each spring's blocks (E, d, d) of `kernels.spring_jacobians`: B = (k - k_t) n nᵀ + k_t I
    into ``stiff`` and, if it is not empty, C = c n nᵀ into ``damp``."""
    dim = x.shape[1]
    n = np.empty(dim)
    for s in range(len(a)):
        squared = 0.0
        for i in range(dim):
            n[i] = x[a[s], i] - x[b[s], i]
            squared += n[i] * n[i]
        length = math.sqrt(squared) if squared > 0.0 else math.inf  # coincident: n = 0
        inverse = 1.0 / length
        for i in range(dim):
            n[i] *= inverse
        across = _transverse_stiffness(k[s], rest[s], length)
        for i in range(dim):
            for j in range(dim):
                stiff[s, i, j] = (k[s] - across) * n[i] * n[j] + (across if i == j else 0.0)
                if len(damp):
                    damp[s, i, j] = c[s] * n[i] * n[j]


@numba.njit(cache=True)
def _divide_by_masses(forces, masses, fixed):
    """Turn forces (N, d) into accelerations in place: a = F/m, and 0 for fixed particles."""
    for i in range(len(masses)):
        inverse = _inverse_mass(masses[i], not fixed[i])
        for q in range(forces.shape[1]):
            forces[i, q] = _acceleration(forces[i, q], inverse)


def _compile_advance(update: Callable, threads: bool) -> Callable:
    """A loop over the particles doing a = (F + m·g)/m then ``update`` per coordinate,
    and the end of the step (`kernels.StepEnd`) if ``floor`` says so.

    F is ``forces`` ((0, d): none) plus the spring forces not yet added to it, in the order the
    spring loops would add them: the threads' ``partial`` forces (T, N, d; T = 0
    if none, see `_spring_forces_parallel`), then the gather's forces by
    coordinate, particle i at ``by_coordinate[q, pad + i]`` (none if it has no
    rows, see `_gather_parallel`). ``floor`` is (normal (d,) or (0,), height,
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
            inverse = _inverse_mass(masses[i], not fixed[i])
            pinned = ending and fixed[i]
            up = 0.0
            kick = 0.0
            for q in range(x.shape[1]):
                total = forces[i, q] if loaded else 0.0
                for t in range(len(partial)):
                    total += partial[t, i, q]
                if gathered:
                    total += by_coordinate[q, pad + i]
                a = _acceleration(total + masses[i] * field[q], inverse)
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


def _references_of_a_private_array() -> int:
    """How many references the memory of a body's spring array has when only the body
    and one view of it refer to it (as in `_shared`)."""
    owner = type("Owner", (), {})()
    owner.array = np.zeros(2)
    view = owner.array[:1]
    return sys.getrefcount(view.base)


_PRIVATE = _references_of_a_private_array()


def _shared(views: tuple[np.ndarray, ...]) -> bool:
    """True if anything besides the body and ``views`` refers to the memory of ``views``.

    A view of ``body.stiffness`` kept by the user could be written at any time
    without touching ``body.parameters_version``; while one exists, the spring
    values are checked at every step.
    """
    return any(sys.getrefcount(view.base) > _PRIVATE for view in views)


# Spring forces not yet added to the force buffer: the threads' buffers (T, N, d), the
# gather's forces by coordinate (d, N + 2·pad) and that pad (see `_compile_advance`).
Pending = tuple[np.ndarray, np.ndarray, int]
# One compiled loop per update function (threaded or not), for the whole process.
_ADVANCES: dict[tuple[Callable, bool], Callable] = {}
_FAILED: set[Callable] = set()  # updates numba cannot compile: they run on arrays


class NumbaKernel:
    """The compiled spring kernel for one body, with what it needs kept between calls.

    Grid bodies whose springs share their values per offset are gathered by
    offset (`grid_stencil`); other bodies go through the edge loop, over the
    springs sorted by their ends (`_edge_list`), with one force buffer per
    extra thread. What is kept is rebuilt when the springs change
    (``body.topology_version``) and re-checked when their values may have
    (``body.parameters_version``, or a view of them kept elsewhere), so edits
    count at once. ``springs`` (indices) restricts a computation to some
    springs, on one thread, in the body's order.
    """

    def __init__(self) -> None:
        self._version = -1
        self._a = self._b = np.zeros(0, dtype=np.int32)
        self._partial: np.ndarray | None = None
        self._none: Pending = (np.zeros((0, 0, 0)), np.zeros((0, 0)), 0)  # see `_no_partial`
        self._threads = 1
        self._stencil_version = -1
        self._stencil: GridStencil | None = None
        self._stencil_values = np.zeros((3, 0))
        self._columns = (np.ones((1, 0)), 1)  # see `_column_masks`
        self._triples: tuple[np.ndarray, ...] = ()  # see `_stencil_triples`, and mask rows
        self._triple_values = np.zeros((0, 3, 4))
        self._scratch = np.zeros((10, 0))  # see `_gather_block`
        self._pad = 0
        self._values_version = -1
        self._uniform = False
        self._order: np.ndarray | None = None
        self._classes_version = -1
        self._classes: tuple[np.ndarray | None, ...] = (None,)  # see `_edge_list`
        self._no_floor = np.zeros(0)
        self._under = np.zeros(0, dtype=bool)  # see `_compile_advance`

    name = "numba"

    def add_spring_forces(
        self,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> tuple[float, float]:
        """Add the spring and dashpot forces (N) to ``out`` (N, d).

        Returns the largest stretch |d|/l and the power (W) the dashpots take.
        """
        return self._spring_forces(body, x, v, out, springs, reduce=True)[:2]

    def _spring_forces(
        self,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None,
        reduce: bool,
    ) -> tuple[float, float, Pending]:
        """`add_spring_forces`, and the spring forces still to add to ``out`` (see
        `_compile_advance`): none with ``reduce``, else the threads' buffers of
        `_spring_forces_parallel` or the gather's forces by coordinate; without
        ``reduce`` ``out`` is scratch: the edge loops clear it, the gather leaves it."""
        none = self._no_partial(x)
        if springs is None:
            stencil = self.grid_stencil(body)
            if stencil is not None:
                threads = self._parallel(body, PARALLEL_MIN_GATHERED)
                gather = _gather_parallel if threads else _gather_serial
                if self._scratch.shape != (10, len(x) + 2 * self._pad):
                    self._scratch = np.zeros((10, len(x) + 2 * self._pad))  # 2-D: x2 = v2 = 0
                triples, _, o2s, rows_of = self._triples
                columns, rows = self._columns
                layout = (stencil.shape, triples, rows_of, o2s, self._triple_values, columns, rows)
                squares, powers = gather(x, v, *layout, self._scratch, out, reduce)
                stretch, power = math.sqrt(squares.max()), float(powers.sum())  # any threads
                if reduce:
                    return stretch, power, none
                return stretch, power, (none[0], self._scratch[6 : 6 + x.shape[1]], self._pad)
        if springs is not None:
            a, b, k, rest, c = (body.spring_a, body.spring_b, *body.spring_values())
            a, b, k, rest, c = (array[springs] for array in (a, b, k, rest, c))
            return *_spring_forces_serial(x, v, a, b, None, k, rest, c, out), none
        arrays = self._edge_list(body)
        if not self._parallel(body):
            if not reduce:
                out.fill(0.0)
            return *_spring_forces_serial(x, v, *arrays, out), none
        if self._partial is None or self._partial.shape[1:] != x.shape:
            self._partial = np.empty((self._threads - 1, *x.shape))
        sums = _spring_forces_parallel(x, v, *arrays, self._partial, out, reduce)
        return *sums, none if reduce else (self._partial, none[1], 0)

    def _no_partial(self, x: np.ndarray) -> Pending:
        """No spring forces pending (see `_compile_advance`)."""
        if self._none[0].shape[1:] != x.shape:
            self._none = (np.zeros((0, *x.shape)), np.zeros((0, 0)), 0)
        return self._none

    def grid_stencil(self, body: Body) -> GridStencil | None:
        """The body's grid stencil if its forces can be gathered by offset now, else None.

        The stencil is found once per topology (``body.topology_version``); that
        each of its blocks has one stiffness, rest length and dashpot is checked
        at every call (one read of the spring values, stopping at the first
        difference), so edits of single springs switch to the edge loop at once.
        """
        if self._stencil_version != body.topology_version:
            self._stencil = grid_stencil(body)
            blocks = 0 if self._stencil is None else len(self._stencil.offsets)
            if self._stencil is not None:
                self._columns = _column_masks(self._stencil.shape, self._stencil.offsets)
                triples, members, o2s = _stencil_triples(self._stencil.offsets)
                reach = int(np.abs(o2s).max(initial=0))
                self._pad = 2 * reach  # see `_react`
                no_spring = len(self._columns[0]) - 1  # the all-zero mask
                rows_of = np.where(members >= 0, o2s + reach, no_spring)
                self._triples = (triples, members, o2s, rows_of)
            self._stencil_values = np.zeros((3, blocks))
            self._stencil_version = body.topology_version
            self._values_version = -1
        if self._stencil is None:
            return None
        values = body.spring_values()
        if body.parameters_version != self._values_version or _shared(values):
            self._uniform = _uniform_blocks(*values, self._stencil.starts, self._stencil_values)
            self._values_version = body.parameters_version
            if self._uniform:
                self._triple_values = _triple_values(self._stencil_values, self._triples[1])
        return self._stencil if self._uniform else None

    def _parallel(self, body: Body, least: int | None = None) -> bool:
        """Whether the springs of ``body`` are worth splitting between threads: at least
        ``least`` of them (default `PARALLEL_MIN_SPRINGS`)."""
        self._threads = numba.get_num_threads()
        least = PARALLEL_MIN_SPRINGS if least is None else least
        return body.n_springs >= least and self._threads > 1

    def dashpot_power(self, body: Body, x: np.ndarray, v: np.ndarray) -> float:
        """Power (W) the dashpots take out of the body at (x, v), always >= 0."""
        a, b, damping = body.spring_a, body.spring_b, body.spring_values()[2]
        if not self._parallel(body):
            return _dashpot_power_serial(x, v, a, b, damping)
        return _dashpot_power_parallel(x, v, a, b, damping, self._threads)

    def elastic_energy(self, body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
        """Energy (J) stored in the springs (or in the given ones) at positions x."""
        arrays = (body.spring_a, body.spring_b, *body.spring_values()[:2])
        if springs is not None:
            return _elastic_energy_serial(x, *(array[springs] for array in arrays))
        if not self._parallel(body):
            return _elastic_energy_serial(x, *arrays)
        return _elastic_energy_parallel(x, *arrays, self._threads)

    @staticmethod
    def jacobians(
        body: Body, x: np.ndarray, pattern: JacobianPattern
    ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v of the springs on ``pattern``, as `kernels.spring_jacobians`,
        with the blocks computed spring by spring."""
        values = body.spring_values()
        dim = x.shape[1]
        stiff = np.empty((body.n_springs, dim, dim))
        damp = np.empty((body.n_springs if values[2].any() else 0, dim, dim))
        _jacobian_blocks(x, body.spring_a, body.spring_b, *values, stiff, damp)
        return pattern.jacobians(stiff, damp if len(damp) else None)

    @staticmethod
    def to_acceleration(body: Body, forces: np.ndarray) -> np.ndarray:
        """Turn forces (N, d) into accelerations a = F/m in place (0 for fixed); return them."""
        _divide_by_masses(forces, body.masses, body.fixed)
        return forces

    def advance(
        self,
        update: Callable,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        end: StepEnd | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """``update(x, v, a, dt, *coefficients)`` with a = (F + m·g)/m (0 if fixed),
        g = ``field`` (d,) in m/s², in one loop, which also does ``end`` if given.

        An update numba cannot compile warns once and runs on whole arrays.
        """
        pending = self._no_partial(x)
        return self._advance(update, body, x, v, forces, pending, field, dt, coefficients, end)

    def advance_with_springs(
        self,
        update: Callable,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        end: StepEnd | None = None,
    ) -> tuple[np.ndarray, np.ndarray, float, float]:
        """The spring forces, then `advance`: (x_new, v_new, largest stretch, dashpot power W).
        The threads' partial spring forces, or the gather's, are added to F in the
        update's loop, not in a pass of their own; ``forces`` is scratch, its content
        not read (the gather does not touch it, so the loop does not read it)."""
        stretch, power, pending = self._spring_forces(body, x, v, forces, None, reduce=False)
        if len(pending[1]):  # the gather's forces by coordinate are all of F
            forces = forces[:0]
        x_new, v_new = self._advance(
            update, body, x, v, forces, pending, field, dt, coefficients, end
        )
        return x_new, v_new, stretch, power

    def _advance(
        self,
        update: Callable,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        pending: Pending,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        end: StepEnd | None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """`advance` with F = ``forces`` plus the spring forces ``pending`` (see
        `_compile_advance`)."""
        threads = len(x) >= PARALLEL_MIN_PARTICLES and numba.get_num_threads() > 1
        if update in _FAILED:
            compiled = None
        elif (update, threads) not in _ADVANCES:
            compiled = _ADVANCES[update, threads] = _compile_advance(update, threads)
        else:
            compiled = _ADVANCES[update, threads]
        if compiled is not None:
            x_new, v_new = np.empty_like(x), np.empty_like(v)
            if end is None:
                floor = (self._no_floor, 0.0, False, False)
            else:
                floor = (end.normal, end.height, True, end.damping)
                if len(self._under) != len(x):
                    self._under = np.zeros(len(x), dtype=bool)
                self._under[:] = False
            try:
                masses, fixed = body.masses, body.fixed
                bad, work = compiled(
                    x, v, forces, pending, field, masses, fixed, dt, coefficients, floor,
                    x_new, v_new, self._under,
                )  # fmt: skip
            except numba.core.errors.NumbaError as error:
                _FAILED.add(update)
                warnings.warn(
                    f"numba cannot compile {update.__qualname__} ({type(error).__name__}); "
                    "it runs on whole numpy arrays instead, with the same result, more slowly",
                    RuntimeWarning,
                    stacklevel=5,
                )
            else:
                if end is not None:
                    end.arrays, end.finite, end.damping_work = (x_new, v_new), bad == 0, work / 2
                    end.under = np.flatnonzero(self._under) if len(end.normal) else None
                return x_new, v_new
        partial, by_coordinate, pad = pending
        forces = forces if len(forces) else np.zeros_like(x)
        for part in partial:
            forces = forces + part  # in the order of `_spring_forces_parallel`
        if len(by_coordinate):
            forces = forces + by_coordinate[:, pad : pad + len(x)].T
        inverse = equations.inverse_mass(body.masses, ~body.fixed)
        a = equations.acceleration(forces + body.masses[:, None] * field, inverse[:, None])
        return update(x, v, a, dt, *coefficients)

    def _edge_list(self, body: Body) -> tuple[np.ndarray | None, ...]:
        """Ends a, b of all springs sorted by (a, b), each one's class (or None) and the
        stiffness, rest length and dashpot of each class (or of each spring).

        In that order consecutive springs share or neighbour their particles,
        so the edge loop reads and writes memory it has just used, whatever
        order the springs were added in (a shuffled 60³ grid: several times
        faster). The ends (uint32: half the memory traffic of int64) and the
        order are kept per topology; the classes (`_spring_classes`) are found
        again when the values may have changed (see `grid_stencil`). Past
        `SPRING_CLASSES` distinct values the loop reads them per spring: the
        body's arrays, or copies in the sorted order.
        """
        if self._version != body.topology_version:
            index = np.uint32 if body.n_particles < 2**32 else np.uint64
            order = np.lexsort((body.spring_b, body.spring_a))
            self._order = None if np.array_equal(order, np.arange(len(order))) else order
            ends = (body.spring_a, body.spring_b)
            if self._order is not None:
                ends = tuple(end[order] for end in ends)
            self._a, self._b = (end.astype(index) for end in ends)
            self._version = body.topology_version
            self._classes_version = -1
        values = body.spring_values()
        shared = _shared(values)
        if body.parameters_version != self._classes_version or shared:
            # sorted springs and a view held: the body's arrays, not classes to find every step
            self._classes = (None,) if shared and self._order is None else self._classify(values)
            self._classes_version = body.parameters_version
        if self._classes[0] is None and self._order is None:
            return self._a, self._b, None, *values  # not kept: a reference would look shared
        return self._a, self._b, *self._classes

    def _classify(self, values: tuple[np.ndarray, ...]) -> tuple[np.ndarray | None, ...]:
        """Each sorted spring's class (uint8 or uint16) and the stiffness (N/m), rest length
        (m) and dashpot (N·s/m) of each class; (None,) past `SPRING_CLASSES` classes,
        with the values in the sorted order if they are not in the body's.

        The classes are found in the body's order (`_spring_classes`, reading memory
        in order), then put in the sorted order: one small array to permute, not three.
        """
        most = min(len(values[0]), SPRING_CLASSES)
        slots = np.zeros(1 << max(4, (2 * most).bit_length()), np.int32)
        kinds = np.empty(len(values[0]), np.uint16)
        table = np.empty((most, 3), np.int64)
        classes = _spring_classes(*(array.view(np.int64) for array in values), slots, kinds, table)
        if classes < 0:
            if self._order is None:
                return (None,)
            return None, *(array[self._order] for array in values)
        table = table[:classes].view(np.float64)
        kinds = kinds.astype(np.uint8) if classes <= 256 else kinds
        if self._order is not None:
            kinds = kinds[self._order]
        return kinds, *(np.ascontiguousarray(column) for column in table.T)
