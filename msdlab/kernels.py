"""Spring physics over whole arrays: forces (eq. 1.1-1.2), energy, power and Jacobians.

Every function takes the spring arrays of a `Body` (``a``, ``b`` particle indices,
``k`` stiffness, ``rest`` rest lengths, ``c`` dashpot coefficients) and computes,
for all springs at once, exactly what `Spring.force` computes for one.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .body import Body


def spring_vectors(body: Body, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Spring vectors x_a - x_b (E, d) and lengths (E,) in m."""
    d = x[body.spring_a] - x[body.spring_b]
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
    pick = slice(None) if springs is None else springs
    a, b = body.spring_a[pick], body.spring_b[pick]
    rest, damping = body.rest_lengths[pick], body.spring_damping[pick]
    d = x[a] - x[b]
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    safe = np.where(length > 0, length, np.inf)  # coincident ends: no direction, no force
    magnitude = body.stiffness[pick] * (rest - length)
    if np.any(damping):
        magnitude -= damping * np.einsum("ij,ij->i", v[a] - v[b], d) / safe
    f = (magnitude / safe)[:, None] * d
    if out is None:
        out = np.zeros_like(x)
    n = len(x)
    for axis in range(x.shape[1]):
        out[:, axis] += np.bincount(a, f[:, axis], n) - np.bincount(b, f[:, axis], n)
    stretch = float(np.max(length / rest)) if len(length) else 0.0
    return out, stretch


def elastic_energy(body: Body, x: np.ndarray, springs: np.ndarray | None = None) -> float:
    """Energy stored in the springs (or in the given ones), Σ ½ k (|x_a - x_b| - l)² (J)."""
    pick = slice(None) if springs is None else springs
    d = x[body.spring_a[pick]] - x[body.spring_b[pick]]
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    return float(0.5 * np.sum(body.stiffness[pick] * (length - body.rest_lengths[pick]) ** 2))


def dashpot_power(body: Body, x: np.ndarray, v: np.ndarray) -> float:
    """Power the dashpots take out of the body, Σ c ((v_a - v_b)·n)² (W), always >= 0."""
    if not np.any(body.spring_damping):
        return 0.0
    d, length = spring_vectors(body, x)
    rate = np.einsum("ij,ij->i", v[body.spring_a] - v[body.spring_b], d) / np.where(
        length > 0, length, np.inf
    )
    return float(np.sum(body.spring_damping * rate**2))


class JacobianPattern:
    """Sparsity of the spring Jacobians (N·d × N·d, CSR), built once per topology.

    Holds the rows and columns of every (a, a), (b, b), (a, b), (b, a) block and
    of the whole diagonal, sorted and merged once, and a sparse map ``assemble``
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
        block_entries = body.n_springs * dim * dim
        signs = np.repeat([-1.0, -1.0, 1.0, 1.0], block_entries)
        entry = np.tile(np.arange(block_entries), 4)
        self.assemble = sp.csr_matrix(
            (signs, (inverse[: len(rows)], entry)), shape=(len(unique), block_entries)
        )

    def matrices(self, *blocks: np.ndarray) -> list[sp.csr_matrix]:
        """One CSR matrix per array of spring blocks (E, d, d), on this pattern."""
        values = np.stack([block.ravel() for block in blocks], axis=1)
        data = self.assemble @ values
        return [
            sp.csr_matrix((data[:, i], self.indices, self.indptr), shape=self.shape, copy=False)
            for i in range(len(blocks))
        ]


def spring_jacobians(
    body: Body, x: np.ndarray, pattern: JacobianPattern | None = None
) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """∂F/∂x and ∂F/∂v (N·d × N·d, sparse) of the spring and dashpot forces.

    Per spring with n = d/|d|, the stiffness block is
    B = k [n nᵀ + max(0, 1 - l/|d|)(I - n nᵀ)] (the transverse part is dropped
    for compressed springs, as Baraff & Witkin do, so -∂F/∂x stays positive
    semi-definite) and the dashpot block is C = c n nᵀ. Both enter as
    -B on the (a, a) and (b, b) blocks and +B on (a, b) and (b, a).
    ``pattern`` reuses the sparsity of an earlier call on the same springs.
    """
    pattern = JacobianPattern(body) if pattern is None else pattern
    dim = x.shape[1]
    d, length = spring_vectors(body, x)
    safe = np.where(length > 0, length, np.inf)
    n = d / safe[:, None]
    outer = n[:, :, None] * n[:, None, :]
    transverse = np.maximum(0.0, 1.0 - body.rest_lengths / safe)
    eye = np.eye(dim)[None]
    stiff = body.stiffness[:, None, None] * (outer + transverse[:, None, None] * (eye - outer))
    damp = body.spring_damping[:, None, None] * outer
    jx, jv = pattern.matrices(stiff, damp)
    return jx, jv


def _block_indices(a: np.ndarray, b: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Row and column indices of the (a,a), (b,b), (a,b), (b,a) blocks of every spring."""
    comp = np.arange(dim)
    firsts = np.stack([a, b, a, b])[:, :, None, None] * dim + comp[:, None]
    seconds = np.stack([a, b, b, a])[:, :, None, None] * dim + comp[None, :]
    rows = np.broadcast_to(firsts, (4, len(a), dim, dim)).ravel()
    cols = np.broadcast_to(seconds, (4, len(a), dim, dim)).ravel()
    return rows, cols
