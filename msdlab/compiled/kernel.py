"""`NumbaKernel`: the compiled spring kernel for one body, choosing the gather or the edge loop."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numba
import numpy as np

from ..body import Body
from ..kernel_results import Advanced, Jacobians, SpringSums
from ..lattice import LatticeSprings
from ..springs import EdgeSprings
from .advance import advance_particles
from .contact import ground_clamp
from .edges import (
    elastic_energy_parallel,
    elastic_energy_serial,
    jacobian_blocks,
    spring_forces_parallel,
    spring_forces_serial,
)
from .gather import gather_parallel, gather_serial, grid_sum_parallel, grid_sum_serial
from .reductions import PARALLEL_MIN_PARTICLES, damping_work, finite
from .stencil import NO_PLAN, padded_shape, plan

if TYPE_CHECKING:
    from ..jacobian import JacobianPattern

# Below this many springs (particles for the update, `PARALLEL_MIN_PARTICLES`) one thread is
# faster than waking the others.
PARALLEL_MIN_SPRINGS = 50_000

# The gather wakes the threads four times a step: it waits for more springs (about 28³ grid).
PARALLEL_MIN_GATHERED = 250_000


# Spring forces not all added up: an (N, d) array of them (the force buffer, or the gather's
# forces by coordinate seen transposed) and the threads' buffers (T, N, d) still to add to it.
Pending = tuple[np.ndarray, np.ndarray]


class NumbaKernel:
    """The compiled spring kernel for one body, with what it needs kept between calls.

    A lattice (`lattice.LatticeSprings`, the springs of `Body.grid`) is gathered
    by offset (`gather`, laid out by `stencil`); an edge list goes through the edge
    loop, over the springs sorted by their ends (`_edge_list`), with one force
    buffer per extra thread. What is kept is rebuilt when the springs change
    (``body.version``, which every edit of the springs counts). ``springs``
    (indices) restricts a computation to some springs, on one thread, in the
    body's order. `finite` and `damping_work` run on the threads for a body big enough
    to share out.
    """

    def __init__(self) -> None:
        self._version = -1
        self._a = self._b = np.zeros(0, dtype=np.int32)
        self._partial: np.ndarray | None = None
        self._no_partial = np.zeros((0, 0, 0))  # no threads' buffers pending
        self._threads = 1
        self._gather = NO_PLAN  # see `stencil.plan`
        self._laid_out: tuple[object, int, EdgeSprings] = (None, -1, EdgeSprings.empty())
        self._forces = np.zeros((0, 0))  # the spring forces of `advance` (scratch)
        self._values: tuple[np.ndarray, ...] = ()  # see `_edge_list`

    name = "numba"
    finite = staticmethod(finite)
    damping_work = staticmethod(damping_work)
    ground_clamp = staticmethod(ground_clamp)  # `interaction.Ground`'s clamp, if present

    def spring_forces(
        self,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> SpringSums:
        """Add the spring and dashpot forces (N) to ``out`` (N, d); the largest stretch
        |d|/l and the power (W) the dashpots take come from the same loop."""
        return SpringSums(*self._spring_forces(body, x, v, out, springs, reduce=True)[:2])

    def _spring_forces(
        self,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None,
        reduce: bool,
    ) -> tuple[float, float, Pending]:
        """`spring_forces`, and where the spring forces are (`Pending`): ``out`` with
        ``reduce``; else ``out`` plus the threads' buffers of `edges.spring_forces_parallel`,
        or the gather's forces by coordinate. Without ``reduce`` ``out`` is scratch: the
        edge loops clear it, the gather leaves it."""
        if self._no_partial.shape[1:] != x.shape:
            self._no_partial = np.zeros((0, *x.shape))
        none = self._no_partial
        lattice, kept = body.spring_set, self._gather
        if springs is None and isinstance(lattice, LatticeSprings):
            if (kept.lattice, kept.version, kept.particles) != (lattice, body.version, len(x)):
                kept = self._gather = plan(lattice, body.version, len(x))  # edited: again
            big = kept.springs >= PARALLEL_MIN_GATHERED
            threads = big and numba.get_num_threads() > 1  # asked only when it matters
            gather = gather_parallel if threads else gather_serial
            memory = kept.memory
            stretch, power = gather(x, v, out, reduce, *kept.arguments)
            if reduce:
                return stretch, power, (out, none)
            by_coordinate = memory.forces[: x.shape[1], memory.pad : memory.pad + len(x)]
            return stretch, power, (by_coordinate.T, none)
        if springs is not None:
            a, b, k, rest, c = (array[springs] for array in self.edges(body).arrays())
            return *spring_forces_serial(x, v, a, b, k, rest, c, out), (out, none)
        arrays = self._edge_list(body)
        if not self._parallel(body):
            if not reduce:
                out.fill(0.0)
            return *spring_forces_serial(x, v, *arrays, out), (out, none)
        if self._partial is None or self._partial.shape[1:] != x.shape:
            self._partial = np.empty((self._threads - 1, *x.shape))
        sums = spring_forces_parallel(x, v, *arrays, self._partial, out, reduce)
        return *sums, (out, none if reduce else self._partial)

    def edges(self, body: Body) -> EdgeSprings:
        """The body's springs as an edge list: its own, or its lattice laid out (kept here,
        made again when the springs are edited)."""
        springs = body.spring_set
        if isinstance(springs, EdgeSprings):
            return springs
        if self._laid_out[0] is not springs or self._laid_out[1] != body.version:
            self._laid_out = (springs, body.version, springs.edges())
        return self._laid_out[2]

    def _parallel(self, body: Body, least: int | None = None) -> bool:
        """Whether the springs of ``body`` are worth splitting between threads: at least
        ``least`` of them (default `PARALLEL_MIN_SPRINGS`)."""
        least = PARALLEL_MIN_SPRINGS if least is None else least
        if body.n_springs < least:
            return False
        self._threads = numba.get_num_threads()
        return self._threads > 1

    def elastic_energy(self, body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
        """Energy (J) stored in the springs (or in the given ones) at positions x; a
        lattice's summed by offset (`gather.grid_sum`)."""
        lattice = body.spring_set
        if springs is None and isinstance(lattice, LatticeSprings):
            grid_sum = grid_sum_parallel if self._parallel(body) else grid_sum_serial
            return grid_sum(x, *padded_shape(lattice), lattice.stiffness, lattice.rest_lengths)
        edges = self.edges(body)
        arrays = (edges.a, edges.b, edges.stiffness, edges.rest_lengths)
        if springs is not None:
            return elastic_energy_serial(x, *(array[springs] for array in arrays), 1)
        if not self._parallel(body):
            return elastic_energy_serial(x, *arrays, 1)
        return elastic_energy_parallel(x, *arrays, self._threads)

    def jacobians(self, body: Body, x: np.ndarray, pattern: JacobianPattern) -> Jacobians:
        """∂F/∂x and ∂F/∂v of the springs on ``pattern``, as `kernels.spring_jacobians`,
        with the blocks computed spring by spring."""
        edges = self.edges(body)
        dim = x.shape[1]
        stiff = np.empty((edges.count, dim, dim))
        damp = np.empty((edges.count if edges.damping.any() else 0, dim, dim))
        jacobian_blocks(x, *edges.arrays(), stiff, damp)
        return Jacobians(*pattern.jacobians(stiff, damp if len(damp) else None))

    def advance(
        self,
        update: Callable,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        forces: np.ndarray | None = None,
    ) -> Advanced:
        """``update(x, v, a, dt, *coefficients)`` with a = (F + m·g)/m (0 if fixed), F the
        spring forces plus ``forces`` (N, d) if given, g = ``field`` (d,) in m/s²: the
        springs' loop, then one loop doing a and the update.

        The spring forces not yet added up (the threads' buffers, or the gather's forces
        by coordinate) are added in the update's loop, not in a pass of their own; the
        other ``forces`` are added there after the springs'. An update numba cannot
        compile warns once and runs on whole arrays.
        """
        if self._forces.shape != x.shape:
            self._forces = np.empty_like(x)
        if forces is None:
            stretch, power, (total, partial) = self._spring_forces(
                body, x, v, self._forces, None, reduce=False
            )
        else:
            self._forces.fill(0.0)
            stretch, power, _ = self._spring_forces(body, x, v, self._forces, None, reduce=True)
            total, partial = self._forces, forces[np.newaxis]
        threads = len(x) >= PARALLEL_MIN_PARTICLES and numba.get_num_threads() > 1
        state = (update, body, x, v, total, partial, field, dt, coefficients)
        x_new, v_new = advance_particles(*state, threads)
        return Advanced(x_new, v_new, stretch, power)

    def _edge_list(self, body: Body) -> tuple[np.ndarray, ...]:
        """Ends a, b of all springs sorted by (a, b), and the stiffness, rest length and
        dashpot of each, in that order.

        In that order consecutive springs share or neighbour their particles,
        so the edge loop reads and writes memory it has just used, whatever
        order the springs were added in (a shuffled 60³ grid: several times
        faster). The ends (uint32: half the memory traffic of int64) are kept per
        topology; the values are the body's own arrays, or copies in the sorted order.
        """
        edges = self.edges(body)
        if self._version != body.version:
            index = np.uint32 if body.n_particles < 2**32 else np.uint64
            order = np.lexsort((edges.b, edges.a))
            in_order = np.array_equal(order, np.arange(len(order)))
            sorted_ = (array if in_order else array[order] for array in edges.arrays())
            a, b, *values = sorted_
            self._a, self._b, self._values = a.astype(index), b.astype(index), tuple(values)
            self._version = body.version
        return self._a, self._b, *self._values
