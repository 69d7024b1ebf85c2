"""Task 2 written a fourth way: np.diff along each axis, the forces padded back into place."""

from __future__ import annotations

import numpy as np


def spring_acceleration(x, spacing, stiffness):
    pos = np.asarray(x, dtype=float)
    acc = np.zeros(pos.shape)
    for ax in (0, 1, 2):
        edge = np.diff(pos, axis=ax)  # x of the next particle along ax minus this one's
        size = np.linalg.norm(edge, axis=3)[..., None]
        safe = np.where(size == 0, 1.0, size)
        tension = np.where(size == 0, 0.0, stiffness * (size - spacing) / safe) * edge
        low_end = [(0, 0)] * 4
        high_end = [(0, 0)] * 4
        low_end[ax], high_end[ax] = (0, 1), (1, 0)
        acc += np.pad(tension, low_end) - np.pad(tension, high_end)
    return acc
