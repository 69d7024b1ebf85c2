"""The edge loop: spring forces, energy and Jacobians of an edge list, one spring at a time.

For each spring it computes the length, the force along it (eq. 1.2 plus the
dashpot), adds it to particle a and its opposite to particle b (eq. 1.1), and
keeps the largest stretch |d|/l and the dashpot power on the way, with no
temporary arrays. Large bodies split the springs between the threads, each
summing into its own force buffer (no two threads write the same memory; the
first one writes the result), and the buffers are then added per particle.
The springs are visited sorted by their ends (see `kernel.NumbaKernel`), so
memory is read in order whatever order they were added in; along the springs
of one first end, its position and force stay in registers.
"""

import numba
import numpy as np

from .equations import dashpot_power, separation, spring_energy, spring_state, transverse_stiffness


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
    """Each spring's blocks (E, d, d) of `kernels.spring_jacobians`: B = (k - k_t) n nᵀ + k_t I
    into ``stiff`` and, if it is not empty, C = c n nᵀ into ``damp``."""
    dim = x.shape[1]
    for s in range(len(a)):
        d = separation(x, a[s], b[s])
        length, safe, _, _ = spring_state(k[s], rest[s], 0.0, d)
        n = (d[0] / safe, d[1] / safe, d[2] / safe)  # 0 for coincident ends: B = k I
        across = transverse_stiffness(k[s], rest[s], length, safe)
        for i in range(dim):
            for j in range(dim):
                stiff[s, i, j] = (k[s] - across) * n[i] * n[j] + (across if i == j else 0.0)
                if len(damp):
                    damp[s, i, j] = c[s] * n[i] * n[j]
