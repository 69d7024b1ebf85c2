"""Compiled (numba) kernels: the physics of `kernels.spring_forces` in one pass, and more.

`kernels.spring_forces` is the readable numpy version: it builds (E, d) arrays
of spring vectors and forces, then sums them per particle. The loop here takes
the springs one by one and computes the same formula (eq. 1.2 plus the dashpot)

    f = [k (l - |d|) - c (v_a - v_b)·d/|d|] d/|d|,   d = x_a - x_b,

adds f to particle a and -f to particle b (eq. 1.1), and keeps the largest
stretch |d|/l on the way, with no temporary arrays. Large bodies split the
springs between the threads, each summing into its own force buffer (no two
threads write the same memory; the first one writes the result), and the
buffers are then added per particle. Dashpot power and elastic energy are
compiled the same way, and so are the updates of `Verlet`, `SymplecticEuler`
and `ExplicitEuler` after the forces, each one loop over the particles with the
operations of the class's `step` in the same order.

The functions are compiled on first use and cached on disk (``cache=True``), so
compiling is paid once per machine and numba version. Set the number of
threads with ``NUMBA_NUM_THREADS`` or `numba.set_num_threads`.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING

# Threads that wait for work sleep instead of spinning. Spinning costs little on
# an idle machine, but when another program holds a core the spinning thread
# keeps the waiting work off the CPU: a 0.5 ms step took 30 ms. Set the
# variable before importing msdlab to choose otherwise.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import numba
import numpy as np

from .integrators import ExplicitEuler, SymplecticEuler, Verlet

if TYPE_CHECKING:
    from .body import Body

# Below this many springs one thread is faster than waking the others.
PARALLEL_MIN_SPRINGS = 50_000


@numba.njit(cache=True, inline="always")
def _add_spring_forces(x, v, a, b, k, rest, c, first, stop, out):
    """Add the forces of springs ``first`` to ``stop - 1`` to ``out`` (2-D or 3-D).

    Returns the largest stretch |d|/l and the dashpot power (W) of those springs.
    """
    three = x.shape[1] == 3
    stretch = 0.0
    power = 0.0
    for s in range(first, stop):
        i, j = a[s], b[s]
        d0 = x[i, 0] - x[j, 0]
        d1 = x[i, 1] - x[j, 1]
        d2 = x[i, 2] - x[j, 2] if three else 0.0
        length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if length > stretch * rest[s]:  # cheaper than dividing for every spring
            stretch = length / rest[s]
        if length == 0.0:  # coincident ends: no direction, no force
            continue
        magnitude = k[s] * (rest[s] - length)
        if c[s] != 0.0:
            closing = (v[i, 0] - v[j, 0]) * d0 + (v[i, 1] - v[j, 1]) * d1
            if three:
                closing += (v[i, 2] - v[j, 2]) * d2
            magnitude -= c[s] * closing / length
            rate = closing / length
            power += c[s] * rate * rate
        scale = magnitude / length
        out[i, 0] += scale * d0
        out[j, 0] -= scale * d0
        out[i, 1] += scale * d1
        out[j, 1] -= scale * d1
        if three:
            out[i, 2] += scale * d2
            out[j, 2] -= scale * d2
    return stretch, power


@numba.njit(cache=True)
def _spring_forces_serial(x, v, a, b, k, rest, c, out):
    """One thread: add every spring's force to ``out``; return (largest stretch, dashpot power)."""
    return _add_spring_forces(x, v, a, b, k, rest, c, 0, len(a), out)


@numba.njit(cache=True, parallel=True)
def _spring_forces_parallel(x, v, a, b, k, rest, c, partial, out):
    """Threads: spring block 0 is summed into ``out``, block t > 0 into ``partial[t - 1]``.

    The partial buffers are then added to ``out`` particle by particle.
    """
    blocks = len(partial) + 1
    count = len(a)
    stretches = np.zeros(blocks)
    powers = np.zeros(blocks)
    for t in numba.prange(blocks):
        first, stop = t * count // blocks, (t + 1) * count // blocks
        if t == 0:
            sums = _add_spring_forces(x, v, a, b, k, rest, c, first, stop, out)
        else:
            partial[t - 1] = 0.0
            sums = _add_spring_forces(x, v, a, b, k, rest, c, first, stop, partial[t - 1])
        stretches[t], powers[t] = sums
    n, dim = out.shape
    for i in numba.prange(n):
        for q in range(dim):
            total = out[i, q]
            for t in range(blocks - 1):
                total += partial[t, i, q]
            out[i, q] = total
    return stretches.max(), powers.sum()


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
                rate = closing / math.sqrt(squared)
                power += c[s] * rate * rate
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
        energy += 0.5 * k[s] * (math.sqrt(squared) - rest[s]) ** 2
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
def _divide_by_masses(forces, masses, fixed):
    """Turn forces (N, d) into accelerations in place: F/m, and 0·F for fixed particles."""
    for i in range(len(masses)):
        inverse = 0.0 if fixed[i] else 1.0 / masses[i]
        for q in range(forces.shape[1]):
            forces[i, q] *= inverse


@numba.njit(cache=True)
def _verlet_update(x, v, forces, masses, fixed, dt, dt2, lam, x_new, v_new):
    """`Verlet.step` after the forces: a = F/m (0 if fixed), x_old = x - v dt,
    x_new = (2 - λ) x - (1 - λ) x_old + a dt², v_new = (x_new - x)/dt; ``dt2`` is dt**2."""
    for i in range(len(masses)):
        inverse = 0.0 if fixed[i] else 1.0 / masses[i]
        for q in range(x.shape[1]):
            a = forces[i, q] * inverse
            x_old = x[i, q] - v[i, q] * dt
            x_new[i, q] = (2.0 - lam) * x[i, q] - (1.0 - lam) * x_old + a * dt2
            v_new[i, q] = (x_new[i, q] - x[i, q]) / dt


@numba.njit(cache=True)
def _symplectic_euler_update(x, v, forces, masses, fixed, dt, x_new, v_new):
    """`SymplecticEuler.step` after the forces: v_new = v + dt a, x_new = x + dt v_new."""
    for i in range(len(masses)):
        inverse = 0.0 if fixed[i] else 1.0 / masses[i]
        for q in range(x.shape[1]):
            v_new[i, q] = v[i, q] + dt * (forces[i, q] * inverse)
            x_new[i, q] = x[i, q] + dt * v_new[i, q]


@numba.njit(cache=True)
def _explicit_euler_update(x, v, forces, masses, fixed, dt, x_new, v_new):
    """`ExplicitEuler.step` after the forces: x_new = x + dt v, v_new = v + dt a."""
    for i in range(len(masses)):
        inverse = 0.0 if fixed[i] else 1.0 / masses[i]
        for q in range(x.shape[1]):
            x_new[i, q] = x[i, q] + dt * v[i, q]
            v_new[i, q] = v[i, q] + dt * (forces[i, q] * inverse)


class CompiledKernels:
    """The compiled kernels for one body, with what they need kept between calls.

    Keeps int32 copies of the spring ends (half the memory traffic of int64)
    and one force buffer per extra thread, rebuilt when the springs change
    (``body.topology_version``). Stiffness, rest lengths and dashpots are read
    from the body at every call, so edits to them count at once. ``springs``
    (indices) restricts a computation to some springs, on one thread.
    """

    def __init__(self) -> None:
        self._version = -1
        self._a = self._b = np.zeros(0, dtype=np.int32)
        self._partial: np.ndarray | None = None
        self._new: tuple[np.ndarray, np.ndarray] | None = None

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
        a, b = self._ends(body)
        arrays = (a, b, body.stiffness, body.rest_lengths, body.spring_damping)
        if springs is not None:
            return _spring_forces_serial(x, v, *(array[springs] for array in arrays), out)
        if self._partial is None:
            return _spring_forces_serial(x, v, *arrays, out)
        return _spring_forces_parallel(x, v, *arrays, self._partial, out)

    def dashpot_power(self, body: Body, x: np.ndarray, v: np.ndarray) -> float:
        """Power (W) the dashpots take out of the body at (x, v), always >= 0."""
        a, b = self._ends(body)
        if self._partial is None:
            return _dashpot_power_serial(x, v, a, b, body.spring_damping)
        return _dashpot_power_parallel(x, v, a, b, body.spring_damping, len(self._partial) + 1)

    def elastic_energy(self, body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
        """Energy (J) stored in the springs (or in the given ones) at positions x."""
        a, b = self._ends(body)
        arrays = (a, b, body.stiffness, body.rest_lengths)
        if springs is not None:
            return _elastic_energy_serial(x, *(array[springs] for array in arrays))
        if self._partial is None:
            return _elastic_energy_serial(x, *arrays)
        return _elastic_energy_parallel(x, *arrays, len(self._partial) + 1)

    @staticmethod
    def has_update(integrator: object) -> bool:
        """True for exactly `Verlet`, `SymplecticEuler`, `ExplicitEuler` (a subclass may
        change `step`)."""
        return type(integrator) in (Verlet, SymplecticEuler, ExplicitEuler)

    def update(
        self,
        body: Body,
        integrator: Verlet | SymplecticEuler | ExplicitEuler,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        dt: float,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The new (x, v) of ``integrator.step`` given the forces at (x, v).

        The arrays returned are buffers reused by the next call.
        """
        kind = type(integrator)
        if self._new is None or self._new[0].shape != x.shape:
            self._new = (np.empty_like(x), np.empty_like(x))
        x_new, v_new = self._new
        args = (x, v, forces, body.masses, body.fixed, dt)
        if kind is Verlet:
            _verlet_update(*args, dt**2, integrator.damping, x_new, v_new)
        elif kind is SymplecticEuler:
            _symplectic_euler_update(*args, x_new, v_new)
        else:
            _explicit_euler_update(*args, x_new, v_new)
        return x_new, v_new

    @staticmethod
    def divide_by_masses(body: Body, forces: np.ndarray) -> None:
        """Turn forces (N, d) into accelerations in place: F/m, and 0·F for fixed particles."""
        _divide_by_masses(forces, body.masses, body.fixed)

    def _ends(self, body: Body) -> tuple[np.ndarray, np.ndarray]:
        """The spring ends as compact integers, and the thread buffers, for this topology."""
        if self._version != body.topology_version:
            index = np.int32 if body.n_particles < 2**31 else np.int64
            self._a = body.spring_a.astype(index)
            self._b = body.spring_b.astype(index)
            threads = numba.get_num_threads()
            parallel = body.n_springs >= PARALLEL_MIN_SPRINGS and threads > 1
            shape = (threads - 1, *body.positions.shape)
            self._partial = np.empty(shape) if parallel else None
            self._version = body.topology_version
        return self._a, self._b
