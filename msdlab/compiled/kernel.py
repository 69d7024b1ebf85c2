"""`NumbaKernel`: the numba backend, the methods of `kernels.NumpyKernel` on compiled loops."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numba
import numpy as np

from ..body import Body
from ..host_state import HostState
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


class NumbaKernel(HostState):
    """The numba backend (`spring_kernel.SpringKernel`), with what a body needs kept between
    calls, made again when its springs are edited (``body.version``).

    A lattice (`lattice.LatticeSprings`, the springs of `Body.grid`) is gathered by
    offset (`gather`, laid out by `stencil`); an edge list goes through the edge loop,
    over the springs sorted by their ends (`_sorted_edges`), with one force buffer per
    extra thread. ``springs`` (indices) restricts a computation to some springs, on one
    thread, in the body's order.
    """

    name = "numba"
    finite = staticmethod(finite)
    damping_work = staticmethod(damping_work)
    ground_clamp = staticmethod(ground_clamp)

    def __init__(self) -> None:
        self._edges: tuple[object, int, EdgeSprings] = (None, -1, EdgeSprings.empty())
        self._sorted: tuple[object, int, tuple[np.ndarray, ...]] = (None, -1, ())
        self._gather = NO_PLAN  # see `stencil.plan`
        self._forces = np.zeros((0, 0))  # the spring forces of `advance`
        self._partial = np.zeros((0, 0, 0))  # the edge loop's extra threads' forces
        self._none = np.zeros((0, 0, 0))  # no threads' forces

    def edges(self, body: Body) -> EdgeSprings:
        """The springs of ``body`` as an edge list (a lattice's laid out once per edit)."""
        if self._edges[0] is not body.spring_set or self._edges[1] != body.version:
            self._edges = (body.spring_set, body.version, body.spring_set.edges())
        return self._edges[2]

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
        if springs is not None:
            a, b, k, rest, c = (array[springs] for array in self.edges(body).arrays())
            return SpringSums(*spring_forces_serial(x, v, a, b, k, rest, c, out))
        return SpringSums(*self._pass(body, x, v, out, fused=False)[:2])

    def elastic_energy(self, body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
        """Energy (J) stored in the springs (or in the given ones) at positions x; a
        lattice's summed by offset (`gather.grid_sum`)."""
        lattice = body.spring_set
        if springs is None and isinstance(lattice, LatticeSprings):
            parallel = lattice.count >= PARALLEL_MIN_SPRINGS and numba.get_num_threads() > 1
            grid_sum = grid_sum_parallel if parallel else grid_sum_serial
            return grid_sum(x, *padded_shape(lattice), lattice.stiffness, lattice.rest_lengths)
        edges = self.edges(body)
        arrays = (edges.a, edges.b, edges.stiffness, edges.rest_lengths)
        if springs is not None:
            return elastic_energy_serial(x, *(array[springs] for array in arrays), 1)
        blocks = numba.get_num_threads() if edges.count >= PARALLEL_MIN_SPRINGS else 1
        energy = elastic_energy_parallel if blocks > 1 else elastic_energy_serial
        return energy(x, *arrays, blocks)

    def jacobians(self, body: Body, x: np.ndarray, pattern: JacobianPattern) -> Jacobians:
        """∂F/∂x and ∂F/∂v of the springs on ``pattern``, as `kernels.jacobians`, with the
        blocks computed spring by spring."""
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
        springs' loop, then one loop doing a and the update (`advance.advance_particles`).

        The spring forces not yet added up (the threads' buffers, or the gather's forces
        by coordinate) are added in the update's loop, not in a pass of their own; the
        other ``forces`` are added there after the springs'.
        """
        if self._forces.shape != x.shape:
            self._forces = np.empty_like(x)
        if forces is None:
            stretch, power, total, partial = self._pass(body, x, v, self._forces, fused=True)
        else:
            self._forces.fill(0.0)
            stretch, power, _, _ = self._pass(body, x, v, self._forces, fused=False)
            total, partial = self._forces, forces[np.newaxis]
        parallel = len(x) >= PARALLEL_MIN_PARTICLES and numba.get_num_threads() > 1
        state = (update, body, x, v, total, partial, field, dt, coefficients)
        return Advanced(*advance_particles(*state, parallel), stretch, power)

    def _pass(
        self, body: Body, x: np.ndarray, v: np.ndarray, out: np.ndarray, fused: bool
    ) -> tuple[float, float, np.ndarray, np.ndarray]:
        """The springs' loop: the largest stretch, the dashpot power (W), and the spring
        forces as an (N, d) array plus the threads' (T, N, d) to add to it.

        Not ``fused``, the forces are added to ``out`` and no threads' are left. ``fused``,
        ``out`` is scratch, and the last sum is left to the caller's loop: the forces are
        ``out`` (cleared first) plus the edge loop's threads' buffers, or the gather's
        forces by coordinate, seen transposed.
        """
        if self._none.shape[1:] != x.shape:
            self._none = np.zeros((0, *x.shape))
        lattice = body.spring_set
        if isinstance(lattice, LatticeSprings):
            kept = self._gather
            if (kept.lattice, kept.version, kept.particles) != (lattice, body.version, len(x)):
                kept = self._gather = plan(lattice, body.version, len(x))
            parallel = kept.springs >= PARALLEL_MIN_GATHERED and numba.get_num_threads() > 1
            gather = gather_parallel if parallel else gather_serial
            stretch, power = gather(x, v, out, not fused, *kept.arguments)
            return stretch, power, kept.forces if fused else out, self._none
        arrays = self._sorted_edges(body)
        blocks = numba.get_num_threads() if len(arrays[0]) >= PARALLEL_MIN_SPRINGS else 1
        if blocks == 1:
            if fused:
                out.fill(0.0)
            return *spring_forces_serial(x, v, *arrays, out), out, self._none
        if self._partial.shape != (blocks - 1, *x.shape):
            self._partial = np.empty((blocks - 1, *x.shape))
        sums = spring_forces_parallel(x, v, *arrays, self._partial, out, not fused)
        return *sums, out, self._partial if fused else self._none

    def _sorted_edges(self, body: Body) -> tuple[np.ndarray, ...]:
        """Ends a, b of all springs sorted by (a, b), and the stiffness, rest length and
        dashpot of each, in that order.

        In that order consecutive springs share or neighbour their particles, so the
        edge loop reads and writes memory it has just used, whatever order the springs
        were added in (a shuffled 60³ grid: several times faster). The ends are uint32
        (half the memory traffic of int64); the values are the body's own arrays, or
        copies in the sorted order.
        """
        if self._sorted[0] is not body.spring_set or self._sorted[1] != body.version:
            edges = self.edges(body)
            order = np.lexsort((edges.b, edges.a))
            if np.array_equal(order, np.arange(len(order))):
                order = slice(None)
            a, b, *values = (array[order] for array in edges.arrays())
            index = np.uint32 if body.n_particles < 2**32 else np.uint64
            arrays = (a.astype(index), b.astype(index), *values)
            self._sorted = (body.spring_set, body.version, arrays)
        return self._sorted[2]
