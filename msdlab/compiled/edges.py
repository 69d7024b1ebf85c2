"""The edge loop: spring forces, energy and Jacobians, one spring at a time.

For each spring it computes the length, the force along it (eq. 1.2 plus the
dashpot), adds it to particle a and its opposite to particle b (eq. 1.1), and
keeps the largest stretch |d|/l and the dashpot power on the way, with no
temporary arrays. Large bodies split the springs between the threads, each
summing into its own force buffer (no two threads write the same memory; the
first one writes the result), and the buffers are then added per particle.
The springs are visited sorted by their ends (see `kernel.NumbaKernel`), so
memory is read in order whatever order they were added in; along the springs
of one first end, its position and force stay in registers. Their stiffness,
rest length and dashpot come from a small table of the distinct triples,
through a one- or two-byte class per spring (`spring_classes`).
"""

import math

import numba
import numpy as np

from .equations import dashpot_power, spring_energy, spring_tension, transverse_stiffness

# Odd constants that mix the bits of the spring values into a hash (see `spring_classes`).
_MIX = (np.uint64(0x9E3779B97F4A7C15), np.uint64(0xC2B2AE3D27D4EB4F), np.uint64(0x165667B19E3779F9))


@numba.njit(cache=True, inline="always")
def _add_spring_forces(x, v, a, b, kinds, k, rest, c, first, stop, out, three):
    """Add the forces of springs ``first`` to ``stop - 1`` to ``out``, (N, 3) if ``three``
    else (N, 2). Returns the largest stretch |d|/l and the dashpot power (W) of those springs.

    Spring s has the stiffness, rest length and dashpot ``k``, ``rest``, ``c`` at
    ``kinds[s]`` (see `spring_classes`), or at s when ``kinds`` is None. Along a
    run of springs with the same end a, a's position and force stay in registers:
    its force is summed in the same order as in memory, so the sums do not change.
    The force is `equations.spring_force`'s, f_a = [k (l - |d|) - c ṡ] d/|d|, with
    |d| and ṡ computed once for the force, the stretch and the dashpot power (the
    same operations, so the same bits).
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
        rate = 0.0  # ṡ = (v_a - v_b)·n, read only for a dashpot
        if c[m] != 0.0:
            w0, w1 = v[i, 0] - v[j, 0], v[i, 1] - v[j, 1]
            w2 = v[i, 2] - v[j, 2] if three else 0.0
            rate = (w0 * d0 + w1 * d1 + w2 * d2) / length
            power += dashpot_power(c[m], rate)
        scale = spring_tension(k[m], rest[m], length, c[m], rate) / length  # |f_a| / |d|
        g0, g1, g2 = scale * d0, scale * d1, scale * d2
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
def _add_spring_block(x, v, a, b, kinds, k, rest, c, first, stop, out):
    """`_add_spring_forces` compiled apart for 2-D and 3-D (``three`` a constant in each)."""
    if x.shape[1] == 3:
        return _add_spring_forces(x, v, a, b, kinds, k, rest, c, first, stop, out, True)
    return _add_spring_forces(x, v, a, b, kinds, k, rest, c, first, stop, out, False)


@numba.njit(cache=True)
def spring_forces_serial(x, v, a, b, kinds, k, rest, c, out):
    """One thread: add every spring's force to ``out``; return (largest stretch, dashpot power)."""
    return _add_spring_block(x, v, a, b, kinds, k, rest, c, 0, len(a), out)


@numba.njit(cache=True, parallel=True)
def spring_forces_parallel(x, v, a, b, kinds, k, rest, c, partial, out, reduce):
    """Threads: spring block 0 is summed into ``out``, block t > 0 into ``partial[t - 1]``.

    With ``reduce`` the partial buffers are then added to ``out`` particle by
    particle; else ``out`` is cleared first (the thread of block 0 does it while
    the others clear theirs) and the caller adds them in its own loop (see
    `advance.compile_advance`).
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
def spring_classes(k_bits, rest_bits, c_bits, slots, kinds, table):
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


@numba.njit(cache=True, inline="always")
def _elastic_energy_of_springs(x, a, b, k, rest, first, stop):
    """Energy (J) stored in springs ``first`` to ``stop - 1``, Σ ½ k (|d| - l)²."""
    energy = 0.0
    for s in range(first, stop):
        i, j = a[s], b[s]
        squared = 0.0
        for q in range(x.shape[1]):
            d = x[i, q] - x[j, q]
            squared += d * d
        energy += spring_energy(k[s], rest[s], math.sqrt(squared))
    return energy


@numba.njit(cache=True)
def elastic_energy_serial(x, a, b, k, rest):
    """One thread: Σ ½ k (|d| - l)² over all springs (J)."""
    return _elastic_energy_of_springs(x, a, b, k, rest, 0, len(a))


@numba.njit(cache=True, parallel=True)
def elastic_energy_parallel(x, a, b, k, rest, blocks):
    """Threads: Σ ½ k (|d| - l)² over all springs (J), in ``blocks`` blocks."""
    count = len(a)
    energies = np.zeros(blocks)
    for t in numba.prange(blocks):
        first, stop = t * count // blocks, (t + 1) * count // blocks
        energies[t] = _elastic_energy_of_springs(x, a, b, k, rest, first, stop)
    return energies.sum()


@numba.njit(cache=True)
def jacobian_blocks(x, a, b, k, rest, c, stiff, damp):
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
        across = transverse_stiffness(k[s], rest[s], length)
        for i in range(dim):
            for j in range(dim):
                stiff[s, i, j] = (k[s] - across) * n[i] * n[j] + (across if i == j else 0.0)
                if len(damp):
                    damp[s, i, j] = c[s] * n[i] * n[j]
