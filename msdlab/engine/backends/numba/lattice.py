"""The numba backend's second loop: a lattice's springs (`lattice.LatticeSprings`, the
springs of `Body.grid`) by neighbour offset, with no list of springs, and its layout.

The layout: the gather walks the particles in C order, each one's springs to the
neighbours ahead of it, three offsets at a time (a triple). The offsets are grouped into
triples, the spring values arranged per triple, and the particles whose neighbour would
leave their grid row masked; all of it is a few small arrays (`Layout`, `Triples`), made
again whenever the lattice is edited, with the loop's scratch memory (`Scratch`).

The loop (`gather`): each particle computes its springs to the neighbours ahead of it
(half the stencil, so each spring once, with `equations.spring_state`, the terms of
`equations.spring_force`), adds their forces to itself and, in a second loop, their
opposites to the neighbours. The positions are copied by coordinate so that the inner
loops walk contiguous memory on vector registers, over whole grid rows (those whose
neighbour would leave its row masked out), three offsets at a time (a particle's position
is read and its force written once for three springs). The threads take grid planes,
every third one at once in three rounds, so that no two write the same particle; one
thread takes them in the same order, with the same sums. The energy (`grid_sum`) visits
each offset's springs in grid order, the threads taking planes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numba
import numpy as np

from ...model.lattice import LatticeSprings
from .equations import dashpot_power, separation, spring_energy, spring_state

# Particles a gather block holds (whole grid rows): long inner loops, enough blocks for threads.
GATHER_BLOCK = 4096


class Triples(NamedTuple):
    """The lattice's offsets, each pointing ahead, three at a time; T triples.

    Triple t joins each particle to those at grid offsets (``ahead[t]``, ``along[t, j]``),
    j = 0, 1, 2 (``ahead``: the first two coordinates, ``along``: the last), by springs
    of ``stiffness``, ``rest_lengths``, ``damping`` and ``inverse_rest_squared`` 1/l²
    (T, 3 each); ``masks[t, j]`` is the row of `column_masks` for that neighbour. A
    place with no spring has all values 0 and the all-zero mask, and fills triples
    from the back, so ``masks[t, 1]`` is that mask for a triple of one spring.
    """

    ahead: np.ndarray
    along: np.ndarray
    masks: np.ndarray
    stiffness: np.ndarray
    rest_lengths: np.ndarray
    damping: np.ndarray
    inverse_rest_squared: np.ndarray


class Layout(NamedTuple):
    """A lattice's grid as the gather reads it: ``shape`` (3,) in C order (2-D as
    (1, n0, n1)), the column masks (`column_masks`) and the number of grid ``rows`` a
    block of work holds."""

    shape: np.ndarray
    columns: np.ndarray
    rows: int


class Scratch(NamedTuple):
    """The gather's memory, particle p at column p + ``pad``: ``positions``,
    ``velocities`` and ``forces`` by coordinate (3, N + 2·pad) and each particle's
    largest squared stretch |d|²/l² (N + 2·pad,). The padding stays zero, so a masked
    neighbour past either end is still in memory."""

    positions: np.ndarray
    velocities: np.ndarray
    forces: np.ndarray
    squared: np.ndarray
    pad: int


def padded_shape(lattice: LatticeSprings) -> tuple[np.ndarray, np.ndarray]:
    """The lattice's shape (3,) and offsets (M, 3), 2-D ones as the plane (1, n0, n1)."""
    missing = 3 - len(lattice.shape)
    offsets = np.zeros((len(lattice.offsets), 3), dtype=np.int64)
    offsets[:, missing:] = lattice.offsets
    return np.array((1,) * missing + lattice.shape, dtype=np.int64), offsets


def layout(lattice: LatticeSprings) -> tuple[Layout, Triples]:
    """The gather's layout of ``lattice`` and its `Triples`, with its values as they are now."""
    shape, offsets = padded_shape(lattice)
    groups: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for m, offset in enumerate(offsets.tolist()):
        o0, o1, o2 = offset if tuple(offset) > (0, 0, 0) else [-o for o in offset]
        groups.setdefault((o0, o1), []).append((o2, m))
    ahead, along, members = [], [], []
    for first_two, group in sorted(groups.items()):
        group = sorted(group) + [(0, -1)] * (-len(group) % 3)
        for start in range(0, len(group), 3):
            ahead.append(first_two)
            along.append([o2 for o2, _ in group[start : start + 3]])
            members.append([m for _, m in group[start : start + 3]])
    along_, member = (np.array(rows, np.int64).reshape(-1, 3) for rows in (along, members))
    columns, rows = column_masks(shape, offsets)
    reach = int(np.abs(offsets[:, 2]).max(initial=0))
    masks = np.where(member >= 0, along_ + reach, len(columns) - 1)
    values = [np.where(member >= 0, array[member], 0.0) for array in lattice.values()]
    with np.errstate(divide="ignore"):
        inverse = np.where(member >= 0, 1.0 / values[1] ** 2, 0.0)
    ahead_ = np.array(ahead, np.int64).reshape(-1, 2)
    return Layout(shape, columns, rows), Triples(ahead_, along_, masks, *values, inverse)


def column_masks(shape: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, int]:
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


def scratch(lattice: LatticeSprings, n_particles: int) -> Scratch:
    """Zeroed scratch memory (`Scratch`) for the gather of ``lattice`` on ``n_particles``."""
    pad = 2 * int(np.abs(lattice.offsets[:, -1]).max(initial=0))  # the last axis's reach, twice
    width = n_particles + 2 * pad
    return Scratch(*np.zeros((3, 3, width)), np.zeros(width), pad)


class Plan(NamedTuple):
    """What the gather of ``lattice`` at ``version`` (`Body.version`) on ``particles``
    particles reads: the fields of its `Layout`, `Triples` and `Scratch` in one tuple
    (``arguments``, the gather's), its scratch ``forces`` by coordinate, seen as (N, d),
    and its number of ``springs``."""

    lattice: LatticeSprings | None
    version: int
    particles: int
    arguments: tuple
    forces: np.ndarray
    springs: int


NO_PLAN = Plan(None, -1, -1, (), np.zeros((0, 0)), 0)


def plan(lattice: LatticeSprings, version: int, n_particles: int) -> Plan:
    """The gather's `Plan` for ``lattice``, edited ``version`` times, on ``n_particles``."""
    grid, triples = layout(lattice)
    memory = scratch(lattice, n_particles)
    forces = memory.forces[: len(lattice.shape), memory.pad : memory.pad + n_particles].T
    arguments = (*grid, *triples, *memory)
    return Plan(lattice, version, n_particles, arguments, forces, lattice.count)


@numba.njit(cache=True, error_model="numpy")
def _pull(y0, y1, y2, x0, x1, x2, q, there, k, rest):
    """The spring from a particle at y to particle ``q``, times ``there`` (1, or 0 when
    that neighbour does not exist): f/|d| of eq. (1.2) (N/m), d = y - x_q (3 components)
    and |d|² (m²). The force on the particle is (f/|d|)·d, on ``q`` its opposite.
    """
    d = (y0 - x0[q], y1 - x1[q], y2 - x2[q])
    length, _, _, scale = spring_state(k, rest, 0.0, d)
    return there * scale, d[0], d[1], d[2], there * length * length


@numba.njit(cache=True, error_model="numpy")
def _pull_damped(y0, y1, y2, u0, u1, u2, xs, vs, q, there, k, rest, c):
    """`_pull` with the dashpot c (N·s/m) on velocities u and vs; also returns its power (W)."""
    x0, x1, x2 = xs
    v0, v1, v2 = vs
    d = (y0 - x0[q], y1 - x1[q], y2 - x2[q])
    length, _, rate, scale = spring_state(k, rest, c, d, (u0 - v0[q], u1 - v1[q], u2 - v2[q]))
    return there * scale, d[0], d[1], d[2], there * length * length, there * dashpot_power(c, rate)


@numba.njit(cache=True, error_model="numpy")
def _push_three(xs, vs, fs, squared, columns, masks, first, stop, shifts, springs, scales, pad):
    """Add to particles ``first`` to ``stop - 1`` the forces of their springs to three
    neighbours, at p + ``shifts[j]``, the same grid row offset apart, and keep each spring's
    f/|d| in ``scales[j, pad + p - first]`` for `_react`. ``xs``, ``vs``, ``fs`` are
    positions, velocities and forces by coordinate, contiguous (vector registers); a
    particle's position is read and its force written once for three springs.
    ``columns[masks[j], p - first]`` is 1 where p has neighbour j, 0 where it would leave
    p's grid row. ``springs`` holds stiffness, rest length, dashpot and 1/rest² (three
    each); ``squared[p]`` keeps the largest |d|²/l² (a running maximum would keep the loop
    scalar). Returns the dashpot power (W); with dashpots the loop stays scalar. Unsigned
    indices spare numba the negative-index test."""
    x0, x1, x2 = xs
    f0, f1, f2 = fs
    ma, mb, mc = masks  # rows of `columns`
    sa, sb, sc = shifts
    (ka, kb, kc), (ra, rb, rc), (ca, cb, cc), (wa, wb, wc) = springs
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
def _push_one(xs, vs, fs, squared, column, first, stop, shift, spring, kept, pad):
    """`_push_three` for a triple holding one spring: to the neighbours at p + ``shift``,
    masked by ``column``, with the stiffness, rest length, dashpot and 1/rest² ``spring``,
    f/|d| kept in ``kept``; the other two would be computed for nothing."""
    x0, x1, x2 = xs
    f0, f1, f2 = fs
    k, rest, c, w = spring
    power = 0.0
    if c == 0.0:  # vector registers, as in `_push_three`
        for i in range(first, stop):
            p, r, q = numba.uint64(i), numba.uint64(i - first), numba.uint64(i + shift)
            a, a0, a1, a2, la = _pull(x0[p], x1[p], x2[p], x0, x1, x2, q, column[r], k, rest)
            f0[p], f1[p], f2[p] = f0[p] + a * a0, f1[p] + a * a1, f2[p] + a * a2
            kept[numba.uint64(i - first + pad)] = a
            squared[p] = max(squared[p], la * w)
        return power
    v0, v1, v2 = vs
    for i in range(first, stop):
        p, r, q = numba.uint64(i), numba.uint64(i - first), numba.uint64(i + shift)
        y, u = (x0[p], x1[p], x2[p]), (v0[p], v1[p], v2[p])
        a, a0, a1, a2, la, pa = _pull_damped(*y, *u, xs, vs, q, column[r], k, rest, c)
        f0[p], f1[p], f2[p] = f0[p] + a * a0, f1[p] + a * a1, f2[p] + a * a2
        kept[numba.uint64(i - first + pad)] = a
        squared[p] = max(squared[p], la * w)
        power += pa
    return power


@numba.njit(cache=True, error_model="numpy")
def _react_one(xs, fs, kept, first, stop, shift, pad):
    """`_react` for a triple holding one spring (see `_push_one`)."""
    x0, x1, x2 = xs
    f0, f1, f2 = fs
    kept[pad + stop - first :] = 0.0
    for i in range(first + shift, stop + shift):
        q, p = numba.uint64(i), numba.uint64(i - shift)
        a = kept[numba.uint64(i - shift - first + pad)]
        f0[q] -= a * (x0[p] - x0[q])
        f1[q] -= a * (x1[p] - x1[q])
        f2[q] -= a * (x2[p] - x2[q])


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
def _push_rows(memory, layout, triples, plane, rows, scales):
    """Add the forces of the springs from the particles of grid rows ``rows`` (first, stop)
    of ``plane`` to their neighbours ahead to both ends; return their dashpot power (W).

    ``memory`` is the `Scratch`, ``layout`` and ``triples`` the
    `Layout` and `Triples`; ``scales``
    (3, rows·n_2 + 2·pad) is the room `_push_three` and `_react` share. For each
    triple of offsets the rows whose neighbours exist are consecutive, so the inner
    loops run over all of them at once, with the column masks for the particles
    whose neighbour would be past the end of their row.
    """
    positions, velocities, forces, squared, pad = memory
    xs = (positions[0], positions[1], positions[2])  # rows, contiguous: vector registers
    vs = (velocities[0], velocities[1], velocities[2])
    fs = (forces[0], forces[1], forces[2])
    columns = layout.columns
    n0, n1, n2 = layout.shape[0], layout.shape[1], layout.shape[2]
    ahead, along, masks, stiffness, rest, damping, inverse = triples  # once: not per triple
    power = 0.0
    for t in range(len(ahead)):
        o0, o1 = ahead[t, 0], ahead[t, 1]
        lo, hi = max(rows[0], -o1), min(rows[1], n1 - o1)  # rows whose neighbours exist
        if not (0 <= plane + o0 < n0 and lo < hi):
            continue
        shift = (o0 * n1 + o1) * n2
        first, stop = (plane * n1 + lo) * n2 + pad, (plane * n1 + hi) * n2 + pad
        shifts = (shift + along[t, 0], shift + along[t, 1], shift + along[t, 2])
        if masks[t, 1] == len(columns) - 1:  # one spring (in the first place, see `Triples`)
            one = (stiffness[t, 0], rest[t, 0], damping[t, 0], inverse[t, 0])
            column = columns[masks[t, 0]]
            power += _push_one(
                xs, vs, fs, squared, column, first, stop, shifts[0], one, scales[0], pad
            )
            _react_one(xs, fs, scales[0], first, stop, shifts[0], pad)
            continue
        three = (masks[t, 0], masks[t, 1], masks[t, 2])
        springs = (
            (stiffness[t, 0], stiffness[t, 1], stiffness[t, 2]),
            (rest[t, 0], rest[t, 1], rest[t, 2]),
            (damping[t, 0], damping[t, 1], damping[t, 2]),
            (inverse[t, 0], inverse[t, 1], inverse[t, 2]),
        )  # numbers, not views: each view of an array costs a reference count
        power += _push_three(
            xs, vs, fs, squared, columns, three, first, stop, shifts, springs, scales, pad
        )
        _react(xs, fs, scales, first, stop, shifts, pad)
    return power


@numba.njit(cache=True, error_model="numpy")
def _push_unit(memory, layout, triples, unit):
    """`_push_rows` for a unit of work: grid plane ``unit`` (3-D), or rows ``unit``·rows
    to (``unit`` + 1)·rows - 1 (2-D), ``layout.rows`` at a time. Returns the largest
    squared stretch |d|²/l² of the springs from its particles and their dashpot power (W).

    A unit's springs reach the next unit only, and its masked neighbours (whose
    force is 0) the one after; so units three apart can be pushed at once.
    """
    n0, n1, n2 = layout.shape[0], layout.shape[1], layout.shape[2]
    rows, pad = layout.rows, memory.pad
    plane, lo, hi = (unit, 0, n1) if n0 > 1 else (0, unit * rows, min(unit * rows + rows, n1))
    scales = np.zeros((3, rows * n2 + 2 * pad))
    power = 0.0
    for first in range(lo, hi, rows):
        power += _push_rows(memory, layout, triples, plane, (first, min(first + rows, hi)), scales)
    start, end = (plane * n1 + lo) * n2 + pad, (plane * n1 + hi) * n2 + pad
    return memory.squared[start:end].max(), power


@numba.njit(cache=True, error_model="numpy")
def _plane_sum(x, shape, offsets, stiffness, rest_lengths, m, plane):
    """Σ over the springs of offset m from the particles of grid ``plane``: their energy
    ½ k (|d| - l)² (J), d = x_p - x_q, with k = ``stiffness[m]`` (N/m) and
    l = ``rest_lengths[m]`` (m)."""
    n1, n2 = shape[1], shape[2]
    o1, o2 = offsets[m, 1], offsets[m, 2]
    k, rest = stiffness[m], rest_lengths[m]
    shift = (offsets[m, 0] * n1 + o1) * n2 + o2
    total = 0.0
    for row in range(max(0, -o1), n1 - max(0, o1)):
        start = (plane * n1 + row) * n2
        for p in range(start + max(0, -o2), start + n2 - max(0, o2)):
            length = spring_state(k, rest, 0.0, separation(x, p, p + shift))[0]
            total += spring_energy(k, rest, length)
    return total


@numba.njit(cache=True, error_model="numpy")
def _totals(squares, powers):
    """The largest stretch |d|/l from the units' largest squared ones, and the units'
    dashpot powers (W) added in order: the same on one thread or several."""
    power = 0.0
    for unit in range(len(powers)):
        power += powers[unit]
    return math.sqrt(squares.max()), power


def _compile(parallel: bool) -> tuple[Callable, Callable]:
    """`gather` and `grid_sum` for threads (``parallel``) or one thread: the same sums."""
    loop = numba.prange if parallel else range

    @numba.njit(cache=True, parallel=parallel, error_model="numpy")
    def gather(x, v, out, add, *lattice):
        """Add to ``out`` (N, d) the forces of a lattice's springs, each computed once, from
        the particle behind (`_push_unit`); return the largest stretch |d|/l and the dashpot
        power (W), summed over the units in order. ``lattice`` is the fields of its
        `Layout`, `Triples` and `Scratch` (plain arrays and numbers: a call types no named
        tuples); without ``add`` the forces stay in the scratch for the caller's loop
        (`kernel.compile_advance`). The threads push every third unit at once, in three
        rounds, so no two write the same particle."""
        layout, triples, memory = (
            Layout(*lattice[:3]),
            Triples(*lattice[3:10]),
            Scratch(*lattice[10:]),
        )
        positions, velocities, forces, squared, pad = lattice[10:]  # arrays, in loops
        damped = np.any(triples.damping != 0.0)
        for p in loop(len(x)):
            for q in range(x.shape[1]):
                positions[q, p + pad] = x[p, q]
                if damped:
                    velocities[q, p + pad] = v[p, q]
            forces[0, p + pad] = forces[1, p + pad] = forces[2, p + pad] = squared[p + pad] = 0.0
        n0, n1, rows = layout.shape[0], layout.shape[1], layout.rows
        units = n0 if n0 > 1 else (n1 + rows - 1) // rows
        squares, powers = np.zeros(units), np.zeros(units)
        for phase in range(3):
            for u in loop((units - phase + 2) // 3):
                unit = phase + 3 * u
                squares[unit], powers[unit] = _push_unit(memory, layout, triples, unit)
        for p in loop(len(x) if add else 0):
            for q in range(x.shape[1]):
                out[p, q] += forces[q, p + pad]
        return _totals(squares, powers)

    @numba.njit(cache=True, parallel=parallel, error_model="numpy")
    def grid_sum(x, shape, offsets, stiffness, rest_lengths):
        """The energy (J) of all springs (see `_plane_sum`), with the ``stiffness`` (N/m)
        and ``rest_lengths`` (m) of each offset (M,); the threads take planes, and the
        sums are added in a fixed order."""
        sums = np.zeros((len(offsets), shape[0]))
        for m in range(len(offsets)):
            for plane in loop(max(0, -offsets[m, 0]), shape[0] - max(0, offsets[m, 0])):
                sums[m, plane] = _plane_sum(x, shape, offsets, stiffness, rest_lengths, m, plane)
        return sums.sum()

    return gather, grid_sum


gather_serial, grid_sum_serial = _compile(False)
gather_parallel, grid_sum_parallel = _compile(True)
