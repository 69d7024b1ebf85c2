"""Many springs drawn fast: one path of separate segments per colour level.

matplotlib's `LineCollection` makes one `Path` object per segment each time its
segments change, which for a body of thousands of springs is most of the time
of an animation frame. `SpringLines` sorts the springs into ``LEVELS`` colour
levels and draws each level as one path of separate segments (move to one end,
line to the other), so a frame costs a few array operations. In 3-D axes the
ends are projected at each draw, as `mpl_toolkits.mplot3d`'s own collections do.
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import Collection, LineCollection
from matplotlib.path import Path
from mpl_toolkits.mplot3d import proj3d

LEVELS = 64  # colours of the scale: steps of 1/64 of its range are not visible


class SpringLines(LineCollection):
    """Springs with ends ``ends`` (E, 2, 2) coloured by ``values`` (E,) on ``cmap`` / ``norm``.

    ``values`` are shown at the middle of their level (of ``LEVELS`` across the
    norm's range; values outside it at the ends). ``ends`` and ``values`` are
    the springs' own data; ``get_array()`` holds the levels' values.
    """

    def __init__(self, ends: np.ndarray, values: np.ndarray, **style: object) -> None:
        super().__init__([], **style)
        self.set_springs(ends, values)

    def set_springs(self, ends: np.ndarray, values: np.ndarray) -> None:
        """New ends (E, 2, d) and values (E,)."""
        self.ends, self.values = np.asarray(ends, dtype=float), np.asarray(values, dtype=float)
        self._set_paths(self.ends)
        self.stale = True

    def _set_paths(self, ends_2d: np.ndarray) -> None:
        """One path per colour level present, holding its springs' segments."""
        fraction = np.ma.filled(self.norm(self.values), 0.5)
        level = np.clip((fraction * LEVELS).astype(int), 0, LEVELS - 1)
        order = np.argsort(level, kind="stable")
        counts = np.bincount(level, minlength=LEVELS)
        points = ends_2d[order].reshape(-1, 2)
        codes = np.tile([Path.MOVETO, Path.LINETO], len(order)).astype(Path.code_type)
        stops = 2 * np.cumsum(counts)
        present = np.flatnonzero(counts)
        paths = [
            Path(points[stops[i] - 2 * counts[i] : stops[i]], codes[: 2 * counts[i]])
            for i in present
        ]
        Collection.set_paths(self, paths)  # LineCollection's own takes plain segments
        self.set_array(self.norm.inverse((present + 0.5) / LEVELS))


class SpringLines3D(SpringLines):
    """`SpringLines` in 3-D axes: the ends (E, 2, 3) are projected when the axes draw."""

    def set_springs(self, ends: np.ndarray, values: np.ndarray) -> None:
        """New ends (E, 2, 3) and values (E,), drawn at the next projection."""
        self.ends, self.values = np.asarray(ends, dtype=float), np.asarray(values, dtype=float)
        self.stale = True

    def do_3d_projection(self) -> float:
        """Project the ends onto the axes (3-D axes call this before drawing); return the
        smallest depth, by which the axes order their collections."""
        x, y, depth = proj3d.proj_transform(*self.ends.reshape(-1, 3).T, self.axes.M)
        self._set_paths(np.stack([x, y], axis=1).reshape(-1, 2, 2))
        return float(np.min(depth, initial=1e9))
