"""The numpy spring kernel: forces (eq. 1.1-1.2), energy, dashpot power and Jacobians of all
springs, on whole arrays.

`NumpyKernel` is the readable reference of the kernel interface
(`spring_kernel.SpringKernel`): the functions of this module, which apply
`msdlab.equations` to the (E, d) arrays of all springs at once. The numba
kernel (`msdlab.compiled.NumbaKernel`, the default) applies the same
equations one spring at a time in compiled loops.

Every function takes the spring arrays of a `Body` (``a``, ``b`` particle indices,
``k`` stiffness, ``rest`` rest lengths, ``c`` dashpot coefficients) and computes,
for all springs at once, what `Spring.force` computes for one.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from . import equations
from .body import Body
from .jacobian import JacobianPattern


def spring_vectors(body: Body, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Spring vectors x_a - x_b (E, d) and lengths (E,) in m."""
    d = x.take(body.spring_a, axis=0) - x.take(body.spring_b, axis=0)
    return d, np.sqrt(np.einsum("ij,ij->i", d, d))


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
    out, stretch, _ = _spring_forces_and_power(body, x, v, out, springs)
    return out, stretch


def _spring_forces_and_power(
    body: Body,
    x: np.ndarray,
    v: np.ndarray,
    out: np.ndarray | None = None,
    springs: np.ndarray | None = None,
) -> tuple[np.ndarray, float, float]:
    """`spring_forces`, and the power (W) the dashpots take at (x, v)."""
    a, b = body.spring_a, body.spring_b
    stiffness, rest, damping = body.spring_values
    if springs is not None:
        a, b, stiffness, rest, damping = (
            values[springs] for values in (a, b, stiffness, rest, damping)
        )
    d = x.take(a, axis=0) - x.take(b, axis=0)
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    power, w = 0.0, np.zeros_like(d[:1])  # without dashpots v_a - v_b is not needed
    if damping.any():
        w = v.take(a, axis=0) - v.take(b, axis=0)
        safe = np.where(length > 0, length, np.inf)  # coincident ends: no rate
        power = float(np.sum(equations.dashpot_power(damping, np.einsum("ij,ij->i", w, d) / safe)))
    along = (*d.T, 0.0)[:3], (*w.T, 0.0)[:3]  # three coordinates each, the third 0 in 2-D
    f = equations.spring_force(stiffness, rest, damping, *along)
    if out is None:
        out = np.zeros_like(x)
    for q in range(x.shape[1]):  # eq. (1.1): f on each a, -f on each b
        out[:, q] += np.bincount(a, f[q], len(x)) - np.bincount(b, f[q], len(x))
    stretch = float((length / rest).max()) if len(length) else 0.0
    return out, stretch, power


def elastic_energy(body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
    """Energy stored in the springs (or in the given ones), Σ ½ k (|x_a - x_b| - l)² (J)."""
    pick = slice(None) if springs is None else springs
    d = x[body.spring_a[pick]] - x[body.spring_b[pick]]
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    stiffness, rest, _ = (values[pick] for values in body.spring_values)
    return float(np.sum(equations.spring_energy(stiffness, rest, length)))


def dashpot_power(body: Body, x: np.ndarray, v: np.ndarray) -> float:
    """Power the dashpots take out of the body, Σ c ((v_a - v_b)·n)² (W), always >= 0."""
    if not np.any(body.spring_values[2]):
        return 0.0
    return _spring_forces_and_power(body, x, v)[2]


def spring_jacobians(
    body: Body, x: np.ndarray, pattern: JacobianPattern | None = None
) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """∂F/∂x and ∂F/∂v (N·d × N·d, sparse) of the spring and dashpot forces.

    Per spring with n = d/|d|, the stiffness block is B = k n nᵀ + k_t (I - n nᵀ),
    k_t = `equations.transverse_stiffness`, and the dashpot block is C = c n nᵀ.
    Both enter as -B on the (a, a) and (b, b) blocks and +B on (a, b) and (b, a).
    ``pattern`` reuses the sparsity of an earlier call on the same springs.
    """
    pattern = JacobianPattern(body) if pattern is None else pattern
    dim = x.shape[1]
    d, length = spring_vectors(body, x)
    safe = np.where(length > 0, length, np.inf)  # coincident ends: n = 0, B = k I
    n = d / safe[:, None]
    outer = n[:, :, None] * n[:, None, :]
    stiffness, rest, damping = body.spring_values
    across = equations.transverse_stiffness(stiffness, rest, safe)[:, None, None]
    stiff = (stiffness[:, None, None] - across) * outer + across * np.eye(dim)
    return pattern.jacobians(stiff, damping[:, None, None] * outer if damping.any() else None)


def finite(x: np.ndarray, v: np.ndarray) -> bool:
    """Whether every position and velocity (N, d) is a finite number."""
    return bool(np.isfinite(x).all() and np.isfinite(v).all())


class NumpyKernel:
    """The readable kernel (`spring_kernel.SpringKernel`): the functions above on whole arrays."""

    name = "numpy"
    elastic_energy = staticmethod(elastic_energy)
    dashpot_power = staticmethod(dashpot_power)
    jacobians = staticmethod(spring_jacobians)
    finite = staticmethod(finite)
    damping_work = staticmethod(equations.damping_work)

    @staticmethod
    def add_spring_forces(
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> tuple[float, float]:
        """Add the spring and dashpot forces (N) to ``out``; return (largest stretch, power W)."""
        _, stretch, power = _spring_forces_and_power(body, x, v, out, springs)
        return stretch, power

    @staticmethod
    def to_acceleration(body: Body, forces: np.ndarray) -> np.ndarray:
        """Accelerations a = F/m (N, d) in m/s² from forces (N, d); 0 for fixed particles."""
        return equations.acceleration(forces, body.masses[:, None], ~body.fixed[:, None])

    @staticmethod
    def acceleration(
        body: Body, x: np.ndarray, v: np.ndarray, forces: np.ndarray, field: np.ndarray
    ) -> tuple[np.ndarray, float, float]:
        """a = (F + m·g)/m (N, d) in m/s², F the spring forces put into ``forces`` (cleared
        first) and g = ``field`` (d,), 0 for fixed particles; with the largest stretch and
        the dashpot power (W)."""
        forces.fill(0.0)
        _, stretch, power = _spring_forces_and_power(body, x, v, forces)
        masses = body.masses[:, None]
        total = forces + masses * field if field.any() else forces
        return equations.acceleration(total, masses, ~body.fixed[:, None]), stretch, power

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
    ) -> tuple[np.ndarray, np.ndarray]:
        """``update(x, v, a, dt, *coefficients)`` on whole arrays, a = (F + m·g)/m (0 if
        fixed), g = ``field`` (d,) in m/s²."""
        masses = body.masses[:, None]
        total = forces + masses * field if field.any() else forces
        return update(
            x, v, equations.acceleration(total, masses, ~body.fixed[:, None]), dt, *coefficients
        )

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
    ) -> tuple[np.ndarray, np.ndarray, float, float]:
        """The spring forces into ``forces`` (cleared first), then the update as `advance`
        does it: (x_new, v_new, largest stretch, dashpot power W)."""
        forces.fill(0.0)
        _, stretch, power = _spring_forces_and_power(body, x, v, forces)
        masses = body.masses[:, None]
        total = forces + masses * field if field.any() else forces
        a = equations.acceleration(total, masses, ~body.fixed[:, None])
        return *update(x, v, a, dt, *coefficients), stretch, power
