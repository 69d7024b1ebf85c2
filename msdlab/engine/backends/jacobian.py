"""The sparsity pattern of the spring Jacobians, built once per topology and refilled.

Implicit integrators need ∂F/∂x and ∂F/∂v (N·d × N·d, sparse). Their entries
sit on the (a, a), (b, b), (a, b) and (b, a) blocks of every spring; this
module finds those places once, so a refill is one sparse product.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..model.springs import EdgeSprings


class JacobianPattern:
    """Sparsity of the spring Jacobians (N·d × N·d, CSR) of the springs ``edges`` between
    ``n_particles`` particles in ``dim`` dimensions, built once per topology (`Layout.pattern`).

    Holds the rows and columns of every (a, a), (b, b), (a, b), (b, a) block and
    of the whole diagonal (``diagonal``: where each (i, i) is in the values),
    sorted and merged once, and a sparse map ``assemble``
    that sums the per-spring blocks (E·d·d values) into the CSR ``data``, -B on
    (a, a) and (b, b), +B on (a, b) and (b, a): refilling is one sparse product.
    """

    def __init__(self, edges: EdgeSprings, n_particles: int, dim: int) -> None:
        n_dof = n_particles * dim
        rows, cols = _block_indices(edges.a, edges.b, dim)
        diagonal = np.arange(n_dof, dtype=np.int64)
        keys = np.concatenate([rows * n_dof + cols, diagonal * (n_dof + 1)])
        unique, inverse = np.unique(keys, return_inverse=True)
        self.shape = (n_dof, n_dof)
        index = np.int32 if len(unique) < 2**31 else np.int64  # what scipy would convert to
        self.indices = (unique % max(n_dof, 1)).astype(index)
        self.indptr = np.zeros(n_dof + 1, dtype=index)
        np.cumsum(np.bincount(unique // max(n_dof, 1), minlength=n_dof), out=self.indptr[1:])
        self.diagonal = np.searchsorted(unique, diagonal * (n_dof + 1))  # where (i, i) is
        block_entries = edges.count * dim * dim
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


def _block_indices(a: np.ndarray, b: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Row and column indices of the (a,a), (b,b), (a,b), (b,a) blocks of every spring."""
    comp = np.arange(dim)
    firsts = np.stack([a, b, a, b])[:, :, None, None] * dim + comp[:, None]
    seconds = np.stack([a, b, b, a])[:, :, None, None] * dim + comp[None, :]
    rows = np.broadcast_to(firsts, (4, len(a), dim, dim)).ravel()
    cols = np.broadcast_to(seconds, (4, len(a), dim, dim)).ravel()
    return rows, cols
