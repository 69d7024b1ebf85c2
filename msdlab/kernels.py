"""The spring kernel: forces (eq. 1.1-1.2), energy, dashpot power and Jacobians of all springs.

`SpringKernel` is the interface `Dynamics` uses; `NumpyKernel` is its readable
reference, the functions of this module applied to whole arrays. The numba
kernel (`msdlab.compiled.NumbaKernel`, the default) applies the same
`msdlab.equations` one spring at a time in compiled loops. `make_kernel` picks one.

Every function takes the spring arrays of a `Body` (``a``, ``b`` particle indices,
``k`` stiffness, ``rest`` rest lengths, ``c`` dashpot coefficients) and computes,
for all springs at once, what `Spring.force` computes for one.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import scipy.sparse as sp

from . import equations
from .body import Body

KERNELS = ("numba", "numpy")
Update = Callable[..., tuple[np.ndarray, np.ndarray]]


@dataclass
class StepEnd:
    """What a `Simulation` does to a step's new (x, v) that an update loop can do as it
    writes them (`Dynamics.advance`): pin the fixed particles (x kept, v = 0), check
    that every value is finite, find the free particles under a floor plane,
    x·normal < height, for the floor to clamp, and, if ``damping``, sum the
    ledger's work of a velocity factor (`energy.damping_work` with factor 0,
    ½ Σ m v·(v + v_new)) over the particles not under the floor.

    A kernel that did it sets ``arrays`` to the (x_new, v_new) it did it to and
    the results; the numpy kernel leaves it to the Simulation's per-array passes.
    """

    normal: np.ndarray  # (d,) unit normal of the floor, or (0,) for no floor
    height: float  # of the floor along the normal (m)
    damping: bool = False
    arrays: tuple[np.ndarray, ...] = ()
    finite: bool = True
    under: np.ndarray | None = None  # indices of the particles found
    damping_work: float = 0.0  # J


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


def component_indices(body: Body, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Where each spring's ends sit in the positions flattened to (N·d,): (E, d) each."""
    components = np.arange(dim)
    return body.spring_a[:, None] * dim + components, body.spring_b[:, None] * dim + components


def _spring_forces_and_power(
    body: Body,
    x: np.ndarray,
    v: np.ndarray,
    out: np.ndarray | None = None,
    springs: np.ndarray | None = None,
    ends: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, float, float]:
    """`spring_forces`, and the power (W) the dashpots take at (x, v).

    ``ends`` may pass `component_indices` (body, d), kept from an earlier call.
    """
    a, b = body.spring_a, body.spring_b
    stiffness, rest, damping = body.spring_values()
    ends_a, ends_b = component_indices(body, x.shape[1]) if ends is None else ends
    if springs is not None:
        a, b, stiffness, rest, damping, ends_a, ends_b = (
            values[springs] for values in (a, b, stiffness, rest, damping, ends_a, ends_b)
        )
    d = x.take(a, axis=0) - x.take(b, axis=0)
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    safe = np.where(length > 0, length, np.inf)  # coincident ends: no direction, no force
    power = 0.0
    rate = 0.0
    if damping.any():
        rate = np.einsum("ij,ij->i", v.take(a, axis=0) - v.take(b, axis=0), d) / safe
        power = float(np.sum(equations.dashpot_power(damping, rate)))
    magnitude = equations.spring_force(stiffness, rest, length, damping, rate)
    f = ((magnitude / safe)[:, None] * d).ravel()  # d = 0 where the ends coincide
    if out is None:
        out = np.zeros_like(x)
    on_a = np.bincount(ends_a.ravel(), f, out.size)
    out += (on_a - np.bincount(ends_b.ravel(), f, out.size)).reshape(out.shape)
    stretch = float((length / rest).max()) if len(length) else 0.0
    return out, stretch, power


def elastic_energy(body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
    """Energy stored in the springs (or in the given ones), Σ ½ k (|x_a - x_b| - l)² (J)."""
    pick = slice(None) if springs is None else springs
    d = x[body.spring_a[pick]] - x[body.spring_b[pick]]
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    stiffness, rest, _ = (values[pick] for values in body.spring_values())
    return float(np.sum(equations.spring_energy(stiffness, rest, length)))


def dashpot_power(body: Body, x: np.ndarray, v: np.ndarray) -> float:
    """Power the dashpots take out of the body, Σ c ((v_a - v_b)·n)² (W), always >= 0."""
    if not np.any(body.spring_values()[2]):
        return 0.0
    return _spring_forces_and_power(body, x, v)[2]


class JacobianPattern:
    """Sparsity of the spring Jacobians (N·d × N·d, CSR), built once per topology.

    Holds the rows and columns of every (a, a), (b, b), (a, b), (b, a) block and
    of the whole diagonal (``diagonal``: where each (i, i) is in the values),
    sorted and merged once, and a sparse map ``assemble``
    that sums the per-spring blocks (E·d·d values) into the CSR ``data``, -B on
    (a, a) and (b, b), +B on (a, b) and (b, a): refilling is one sparse product.
    """

    def __init__(self, body: Body) -> None:
        dim = body.dim or 3
        n_dof = body.n_particles * dim
        rows, cols = _block_indices(body.spring_a, body.spring_b, dim)
        diagonal = np.arange(n_dof, dtype=np.int64)
        keys = np.concatenate([rows * n_dof + cols, diagonal * (n_dof + 1)])
        unique, inverse = np.unique(keys, return_inverse=True)
        self.topology_version = body.topology_version
        self.shape = (n_dof, n_dof)
        index = np.int32 if len(unique) < 2**31 else np.int64  # what scipy would convert to
        self.indices = (unique % max(n_dof, 1)).astype(index)
        self.indptr = np.zeros(n_dof + 1, dtype=index)
        np.cumsum(np.bincount(unique // max(n_dof, 1), minlength=n_dof), out=self.indptr[1:])
        self.diagonal = np.searchsorted(unique, diagonal * (n_dof + 1))  # where (i, i) is
        block_entries = body.n_springs * dim * dim
        signs = np.repeat([-1.0, -1.0, 1.0, 1.0], block_entries)
        entry = np.tile(np.arange(block_entries), 4)
        self.assemble = sp.csr_matrix(
            (signs, (inverse[: len(rows)], entry)), shape=(len(unique), block_entries)
        )

    def jacobians(
        self, stiff: np.ndarray, damp: np.ndarray | None
    ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v on this pattern from the springs' blocks B and C (E, d, d);
        ``damp`` None (no dashpots) gives a ∂F/∂v with no entries to add up."""
        blocks = [stiff] if damp is None else [stiff, damp]
        values = np.stack([block.ravel() for block in blocks], axis=1)
        data = self.assemble @ values
        if damp is None:
            return self.matrix(data[:, 0]), sp.csr_matrix(self.shape)
        return self.matrix(data[:, 0]), self.matrix(data[:, 1])

    def matrix(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix with values ``data`` on this pattern."""
        return sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape, copy=False)


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
    stiffness, rest, damping = body.spring_values()
    across = equations.transverse_stiffness(stiffness, rest, safe)[:, None, None]
    stiff = (stiffness[:, None, None] - across) * outer + across * np.eye(dim)
    return pattern.jacobians(stiff, damping[:, None, None] * outer if damping.any() else None)


def _block_indices(a: np.ndarray, b: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Row and column indices of the (a,a), (b,b), (a,b), (b,a) blocks of every spring."""
    comp = np.arange(dim)
    firsts = np.stack([a, b, a, b])[:, :, None, None] * dim + comp[:, None]
    seconds = np.stack([a, b, b, a])[:, :, None, None] * dim + comp[None, :]
    rows = np.broadcast_to(firsts, (4, len(a), dim, dim)).ravel()
    cols = np.broadcast_to(seconds, (4, len(a), dim, dim)).ravel()
    return rows, cols


class SpringKernel(Protocol):
    """What `Dynamics` needs from a spring kernel; `NumpyKernel` and `NumbaKernel` have it."""

    name: str

    def add_spring_forces(
        self, body: Body, x: np.ndarray, v: np.ndarray, out: np.ndarray, springs: np.ndarray | None
    ) -> tuple[float, float]:
        """Add the spring and dashpot forces (N) to ``out``; return (largest stretch, power W)."""

    def elastic_energy(self, body: Body, x: np.ndarray, springs: np.ndarray | None) -> float:
        """Energy (J) stored in the springs (or in the given ones)."""

    def dashpot_power(self, body: Body, x: np.ndarray, v: np.ndarray) -> float:
        """Power (W) the dashpots take out at (x, v)."""

    def jacobians(
        self, body: Body, x: np.ndarray, pattern: JacobianPattern
    ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v of the springs on ``pattern`` (see `spring_jacobians`)."""

    def to_acceleration(self, body: Body, forces: np.ndarray) -> np.ndarray:
        """Accelerations a = F/m (N, d) from forces (N, d), 0 for fixed (may reuse ``forces``)."""

    def advance(
        self,
        update: Update,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        end: StepEnd | None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """``update(x, v, a, dt, *coefficients)`` with a = (F + m·g)/m, g = ``field`` (d,)
        in m/s² (0 for fixed particles); and ``end``, if given, if the kernel can."""

    def advance_with_springs(
        self,
        update: Update,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        end: StepEnd | None,
    ) -> tuple[np.ndarray, np.ndarray, float, float]:
        """The spring forces, then `advance`: (x_new, v_new, largest stretch, dashpot power W).
        ``forces`` (N, d) is the kernel's scratch: its content is not read."""


class NumpyKernel:
    """The readable kernel: the functions above on whole arrays."""

    name = "numpy"

    def __init__(self) -> None:
        self._version = -1
        self._ends = (np.zeros((0, 3), dtype=np.int64),) * 2  # `component_indices` of the body

    def add_spring_forces(
        self,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        out: np.ndarray,
        springs: np.ndarray | None = None,
    ) -> tuple[float, float]:
        """Add the spring and dashpot forces (N) to ``out``; return (largest stretch, power W)."""
        if self._version != body.topology_version or self._ends[0].shape[1:] != x.shape[1:]:
            self._ends = component_indices(body, x.shape[1])
            self._version = body.topology_version
        _, stretch, power = _spring_forces_and_power(body, x, v, out, springs, self._ends)
        return stretch, power

    def elastic_energy(self, body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
        """Energy (J) stored in the springs (or in the given ones)."""
        return elastic_energy(body, x, springs)

    def dashpot_power(self, body: Body, x: np.ndarray, v: np.ndarray) -> float:
        """Power (W) the dashpots take out at (x, v)."""
        return dashpot_power(body, x, v)

    def jacobians(
        self, body: Body, x: np.ndarray, pattern: JacobianPattern
    ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v of the springs on ``pattern`` (see `spring_jacobians`)."""
        return spring_jacobians(body, x, pattern)

    def to_acceleration(self, body: Body, forces: np.ndarray) -> np.ndarray:
        """Accelerations a = F/m (N, d) in m/s² from forces (N, d); 0 for fixed particles."""
        inverse = equations.inverse_mass(body.masses, ~body.fixed)
        return equations.acceleration(forces, inverse[:, None])

    def advance(
        self,
        update: Update,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        end: StepEnd | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """``update(x, v, a, dt, *coefficients)`` on whole arrays, a = (F + m·g)/m (0 if
        fixed), g = ``field`` (d,) in m/s². ``end`` is left to the Simulation."""
        total = forces + body.masses[:, None] * field if field.any() else forces
        return update(x, v, self.to_acceleration(body, total), dt, *coefficients)

    def advance_with_springs(
        self,
        update: Update,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
        end: StepEnd | None = None,
    ) -> tuple[np.ndarray, np.ndarray, float, float]:
        """`add_spring_forces` to ``forces`` (cleared first), then `advance`: (x_new, v_new,
        largest stretch, dashpot power W)."""
        forces.fill(0.0)
        stretch, power = self.add_spring_forces(body, x, v, forces, None)
        return *self.advance(update, body, x, v, forces, field, dt, coefficients), stretch, power


def default_kernel() -> str:
    """The spring kernel to use: ``MSDLAB_KERNEL`` if set, else "numba".

    "numba" is the compiled loop of `msdlab.compiled`; "numpy" is the readable
    array version of this module. Both apply the same `msdlab.equations`.
    """
    name = os.environ.get("MSDLAB_KERNEL", "").strip().lower()
    return checked_kernel_name(name, "MSDLAB_KERNEL") if name else "numba"


def checked_kernel_name(name: str, what: str) -> str:
    """``name`` if it is a kernel's name, else a ValueError naming ``what`` and the choices."""
    if name not in KERNELS:
        raise ValueError(f"{what} must be one of {', '.join(KERNELS)}, got {name!r}")
    return name


def make_kernel(name: str | None = None) -> SpringKernel:
    """The kernel called ``name`` ("numba" or "numpy"; default `default_kernel()`).

    numba is a dependency of msdlab; if it cannot be imported (a broken
    install), this warns and returns the numpy kernel, which computes the same.
    """
    name = default_kernel() if name is None else checked_kernel_name(name, "kernel")
    if name == "numpy":
        return NumpyKernel()
    try:
        from .compiled import NumbaKernel  # the one optional, compiled backend
    except ImportError as error:
        warnings.warn(
            f"the numba kernel is unavailable ({error}); using the numpy kernel, which "
            'computes the same more slowly. Reinstall with pip install -e ".[test]" to fix it.',
            RuntimeWarning,
            stacklevel=3,
        )
        return NumpyKernel()
    return NumbaKernel()
