"""The numba spring kernel: the same `msdlab.equations`, compiled into loops over the springs.

`kernels.NumpyKernel` applies the equations to (E, d) arrays of all springs,
then sums them per particle. `NumbaKernel` compiles the same functions of
`msdlab.equations` and applies them to the springs one by one: for each it
computes the length, the force along it (eq. 1.2 plus the dashpot), adds it to
particle a and its opposite to particle b (eq. 1.1), and keeps the largest
stretch |d|/l and the dashpot power on the way, with no temporary arrays.
Large bodies split the springs between the threads, each summing into its own
force buffer (no two threads write the same memory; the first one writes the
result), and the buffers are then added per particle.

`NumbaKernel.advance` compiles an integrator's update function (for example
`integrators.verlet_update`) into one loop over the particles that computes
a = F/m and the update together; it is compiled once per process and update.

The spring loops are compiled on first use and cached on disk (``cache=True``),
so compiling is paid once per machine and numba version. Set the number of
threads with ``NUMBA_NUM_THREADS`` or `numba.set_num_threads`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import numba
import numpy as np

from . import equations
from .body import Body

# Below this many springs one thread is faster than waking the others.
PARALLEL_MIN_SPRINGS = 50_000

_spring_force = numba.njit(cache=True, inline="always")(equations.spring_force)
_spring_energy = numba.njit(cache=True, inline="always")(equations.spring_energy)
_dashpot_power_of = numba.njit(cache=True, inline="always")(equations.dashpot_power)
_inverse_mass = numba.njit(cache=True, inline="always")(equations.inverse_mass)
_acceleration = numba.njit(cache=True, inline="always")(equations.acceleration)


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
        closing = 0.0
        if c[s] != 0.0:
            closing = (v[i, 0] - v[j, 0]) * d0 + (v[i, 1] - v[j, 1]) * d1
            if three:
                closing += (v[i, 2] - v[j, 2]) * d2
            power += _dashpot_power_of(c[s], closing / length)
        scale = _spring_force(k[s], rest[s], length, c[s], closing) / length
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
def _divide_by_masses(forces, masses, fixed):
    """Turn forces (N, d) into accelerations in place: a = F/m, and 0 for fixed particles."""
    for i in range(len(masses)):
        inverse = _inverse_mass(masses[i], not fixed[i])
        for q in range(forces.shape[1]):
            forces[i, q] = _acceleration(forces[i, q], inverse)


def _compile_advance(update: Callable) -> Callable:
    """A loop over the particles doing a = F/m then ``update`` per coordinate.

    numba compiles it at its first call, which raises a numba error if it cannot.
    """
    scalar = numba.njit(update)

    @numba.njit
    def advance(x, v, forces, masses, fixed, dt, coefficients, x_new, v_new):
        for i in range(len(masses)):
            inverse = _inverse_mass(masses[i], not fixed[i])
            for q in range(x.shape[1]):
                a = _acceleration(forces[i, q], inverse)
                x_new[i, q], v_new[i, q] = scalar(x[i, q], v[i, q], a, dt, *coefficients)

    return advance


# One compiled loop per update function, for the whole process.
_ADVANCES: dict[Callable, Callable | None] = {}


class NumbaKernel:
    """The compiled spring kernel for one body, with what it needs kept between calls.

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
        dt: float,
        coefficients: tuple[float, ...],
    ) -> tuple[np.ndarray, np.ndarray]:
        """``update(x, v, a, dt, *coefficients)`` with a = F/m (0 if fixed), in one loop.

        An update numba cannot compile warns once and runs on whole arrays.
        """
        if update not in _ADVANCES:
            _ADVANCES[update] = _compile_advance(update)
        compiled = _ADVANCES[update]
        if compiled is not None:
            x_new, v_new = np.empty_like(x), np.empty_like(v)
            try:
                compiled(x, v, forces, body.masses, body.fixed, dt, coefficients, x_new, v_new)
                return x_new, v_new
            except numba.core.errors.NumbaError as error:
                _ADVANCES[update] = None
                warnings.warn(
                    f"numba cannot compile {update.__qualname__} ({type(error).__name__}); "
                    "it runs on whole numpy arrays instead, with the same result, more slowly",
                    RuntimeWarning,
                    stacklevel=4,
                )
        inverse = equations.inverse_mass(body.masses, ~body.fixed)
        return update(x, v, equations.acceleration(forces, inverse[:, None]), dt, *coefficients)

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
