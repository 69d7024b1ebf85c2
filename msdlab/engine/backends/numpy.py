"""The numpy backend: forces (eq. 1.1-1.2), energy, dashpot power and Jacobians of all
springs, a step's update, and the ground's clamp, on whole arrays.

`NumpyKernel` is the readable reference of the backend contract
(`contract.SpringKernel`): the functions of this module, which apply
`msdlab.engine.equations` to the (E, d) arrays of all springs at once. Every other
backend is tested against it, method by method. The numba backend
(`msdlab.engine.backends.numba.NumbaKernel`, the default) applies the same equations one
spring or particle at a time in compiled loops.

Every function reads a body's springs as an edge list (`springs.EdgeSprings`: ``a``,
``b`` particle indices, stiffness, rest lengths, dashpots; a lattice laid out) and
computes, for all springs at once, what `Spring.force` computes for one. `NumpyKernel`
reads them from the `layout.Layout` it is given, which lays a lattice out once per edit.
"""

from __future__ import annotations

import numpy as np

from .. import equations
from ..model.body import Body
from ..model.springs import EdgeSprings
from .contract import Advanced, Jacobians, SpringSums, Update
from .jacobian import JacobianPattern
from .layout import Layout


def spring_vectors(body: Body, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Spring vectors x_a - x_b (E, d) and lengths (E,) in m."""
    return vectors(body.edges(), x)


def vectors(edges: EdgeSprings, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`spring_vectors` of the springs ``edges``."""
    d = x.take(edges.a, axis=0) - x.take(edges.b, axis=0)
    return d, equations.spring_state(0.0, 0.0, 0.0, three(d))[0]


def three(vectors: np.ndarray) -> tuple[np.ndarray, ...]:
    """The three coordinates of (E, d) ``vectors``, (E,) each, the third 0 in 2-D."""
    return (*vectors.T, 0.0)[:3]


def spring_forces(
    body: Body,
    x: np.ndarray,
    v: np.ndarray,
    out: np.ndarray | None = None,
    springs: np.ndarray | None = None,
) -> tuple[np.ndarray, float]:
    """Sum of spring and dashpot forces on each particle (N, d) in N, and the largest stretch.

    Per spring, eq. (1.2) plus the dashpot along it: the force on ``a`` is
    f = [k (l - |d|) - c (v_a - v_b)·d/|d|] d/|d| with d = x_a - x_b, and ``b``
    gets -f. Eq. (1.1) sums these per particle. The stretch is max |d|/l
    (used to detect blow-ups); zero-length springs exert no force. ``springs``
    restricts the sum to some springs (indices).
    """
    out = np.zeros_like(x) if out is None else out
    return out, NumpyKernel().spring_forces(Layout(body), x, v, out, springs).stretch


def elastic_energy(body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
    """Energy stored in the springs (or in the given ones), Σ ½ k (|x_a - x_b| - l)² (J)."""
    return energy(body.edges(), x, springs)


def energy(edges: EdgeSprings, x: np.ndarray, springs: np.ndarray | None = None) -> float:
    """`elastic_energy` of the springs ``edges``."""
    pick = slice(None) if springs is None else springs
    stiffness, rest = edges.stiffness[pick], edges.rest_lengths[pick]
    d = three(x[edges.a[pick]] - x[edges.b[pick]])
    length = equations.spring_state(stiffness, rest, 0.0, d)[0]
    return float(np.sum(equations.spring_energy(stiffness, rest, length)))


def spring_jacobians(
    body: Body, x: np.ndarray, pattern: JacobianPattern | None = None
) -> Jacobians:
    """∂F/∂x and ∂F/∂v (N·d × N·d, sparse) of the spring and dashpot forces (`jacobians`)."""
    layout = Layout(body)
    return jacobians(layout.edges, x, layout.pattern if pattern is None else pattern)


def jacobians(edges: EdgeSprings, x: np.ndarray, pattern: JacobianPattern) -> Jacobians:
    """`spring_jacobians` of the springs ``edges``, on the sparsity ``pattern`` of an
    earlier call on the same springs.

    Per spring with n = d/|d|, the stiffness block B = k n nᵀ + k_t (I - n nᵀ) and the
    dashpot block C = c n nᵀ of `equations.spring_jacobian`, -B on the (a, a) and (b, b)
    blocks and +B on (a, b) and (b, a).
    """
    dim = x.shape[1]
    d = x.take(edges.a, axis=0) - x.take(edges.b, axis=0)
    stiffness, rest, damping = edges.values()
    length, safe, _, _ = equations.spring_state(stiffness, rest, 0.0, three(d))
    n = d / safe[:, None]  # 0 for coincident ends: B = k I
    across = equations.transverse_stiffness(stiffness, rest, length, safe)[:, None, None]
    k, c = stiffness[:, None, None], damping[:, None, None]
    stiff, damp = equations.spring_jacobian(k, across, c, n[:, :, None], n[:, None, :], np.eye(dim))
    return Jacobians(*pattern.jacobians(stiff, damp if damping.any() else None))


def finite(x: np.ndarray, v: np.ndarray) -> bool:
    """Whether every position and velocity (N, d) is a finite number."""
    return bool(np.isfinite(x).all() and np.isfinite(v).all())


def ground_clamp(
    x: np.ndarray,
    v: np.ndarray,
    x_old: np.ndarray,
    v_old: np.ndarray,
    masses: np.ndarray,
    fixed: np.ndarray,
    normal: np.ndarray,
    height: float,
    dt: float,
    friction: float,
) -> float:
    """Put the free particles with x·n < ``height`` back on the plane, in place, and return the
    energy (J) the ground removed (`equations.ground_contact` per particle).

    ``normal`` n (d,) is a unit vector; x, v are the step's new state (N, d), x_old and v_old
    its start.
    """
    above = x @ normal
    candidates = (above < height).nonzero()[0]
    below = candidates[~fixed[candidates]]  # fixed ones only among the few below
    if len(below) == 0:
        return 0.0
    dim = x.shape[1]
    rows = np.zeros((4, 3, len(below)))  # x, v, x_old, v_old of those below; third 0 in 2-D
    for k, array in enumerate((x, v, x_old, v_old)):
        rows[k, :dim] = array.take(below, axis=0).T
    n = np.zeros(3)
    n[:dim] = normal
    put, speed, removed = equations.ground_contact(
        masses.take(below), rows[0], above.take(below), *rows[1:], n, height, dt, 1.0 - friction
    )
    x[below] = np.column_stack(put[:dim])
    v[below] = np.column_stack(speed[:dim])
    return float(np.sum(removed))


class NumpyKernel:
    """The readable kernel (`contract.SpringKernel`): the equations on whole arrays.

    It reads a body's springs as the edge list of the `Layout` it is given (a lattice laid
    out once per edit).
    """

    name = "numpy"
    finite = staticmethod(finite)
    damping_work = staticmethod(equations.damping_work)
    ground_clamp = staticmethod(ground_clamp)

    def spring_forces(
        self,
        layout: Layout,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> SpringSums:
        """Add `spring_forces` to ``out`` (N, d); with the largest stretch and the power (W)
        the dashpots take at (x, v), Σ c ((v_a - v_b)·n)²."""
        edges = layout.edges
        a, b, stiffness, rest, damping = (
            edges.a, edges.b, edges.stiffness, edges.rest_lengths, edges.damping
        )  # fmt: skip
        if springs is not None:
            a, b, stiffness, rest, damping = (
                values[springs] for values in (a, b, stiffness, rest, damping)
            )
        d = (*(x.take(a, axis=0) - x.take(b, axis=0)).T, 0.0)[:3]  # the third 0 in 2-D
        w = None  # v_a - v_b, needed only with dashpots
        if damping.any():
            w = (*(v.take(a, axis=0) - v.take(b, axis=0)).T, 0.0)[:3]
        f, length, rate = equations.spring_force(stiffness, rest, damping, d, w)
        power = 0.0 if w is None else float(np.sum(equations.dashpot_power(damping, rate)))
        for q in range(x.shape[1]):  # eq. (1.1): f on each a, -f on each b
            out[:, q] += np.bincount(a, f[q], len(x)) - np.bincount(b, f[q], len(x))
        stretch = float((length / rest).max()) if len(length) else 0.0
        return SpringSums(stretch, power)

    def elastic_energy(
        self, layout: Layout, x: np.ndarray, springs: np.ndarray | None = None
    ) -> float:
        """`energy` of the body's springs (J)."""
        return energy(layout.edges, x, springs)

    def jacobians(self, layout: Layout, x: np.ndarray) -> Jacobians:
        """`jacobians` of the body's springs, on the layout's pattern."""
        return jacobians(layout.edges, x, layout.pattern)

    def advance(
        self,
        update: Update,
        layout: Layout,
        x: np.ndarray,
        v: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        forces: np.ndarray | None = None,
    ) -> Advanced:
        """``update(x, v, a, dt, *coefficients)`` on whole arrays, a = (F + m·g)/m (0 if fixed):
        F the spring forces plus ``forces`` (N, d) if given, g = ``field`` (d,) in m/s²."""
        total = np.zeros_like(x)
        sums = self.spring_forces(layout, x, v, total)
        total = total if forces is None else total + forces
        masses = layout.masses[:, None]
        if field.any():
            total += masses * field
        a = equations.acceleration(total, masses, ~layout.fixed[:, None])
        x_new, v_new = update(x, v, a, dt, *coefficients)
        if np.may_share_memory(x_new, x) or np.may_share_memory(x_new, v):
            x_new = np.array(x_new)  # an update that returned x: new arrays all the same
        if np.may_share_memory(v_new, v) or np.may_share_memory(v_new, x):
            v_new = np.array(v_new)
        return Advanced(x_new, v_new, *sums)
