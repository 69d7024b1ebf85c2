"""Rotation matrices: a right-handed turn by an angle, in 2-D or about an axis in 3-D."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np


def rotation_matrix(angle_degrees: float, axis: Sequence[float] | None = None) -> np.ndarray:
    """Right-handed rotation by ``angle_degrees``: 2×2 in 2-D (no axis), 3×3 about ``axis``."""
    angle = math.radians(angle_degrees)
    c, s = math.cos(angle), math.sin(angle)
    if axis is None:
        return np.array([[c, -s], [s, c]])
    axis = np.asarray(axis, dtype=float)
    norm = np.linalg.norm(axis)
    if axis.shape != (3,) or not np.isfinite(norm) or norm == 0:
        raise ValueError(f"rotation axis must be a non-zero 3-vector, got {axis.tolist()}")
    x, y, z = axis / norm
    cross = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return c * np.eye(3) + s * cross + (1 - c) * np.outer([x, y, z], [x, y, z])


def checked_rotation(rotation: object, dim: int | None) -> np.ndarray:
    """``rotation`` as an orthogonal (dim, dim) float matrix, else ValueError."""
    matrix = np.asarray(rotation, dtype=float)
    if matrix.shape != (dim, dim) or not np.allclose(matrix @ matrix.T, np.eye(dim), atol=1e-9):
        raise ValueError(f"rotation must be an orthogonal ({dim}, {dim}) matrix")
    return matrix
