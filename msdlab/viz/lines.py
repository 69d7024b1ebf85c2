"""Many springs drawn fast: the springs of one colour level drawn as one shape.

matplotlib's `LineCollection` makes one `Path` object per segment each time its
segments change, which for a body of thousands of springs is most of the time
of an animation frame. `SpringLines` sorts the springs into ``LEVELS`` colour
levels and draws each level as one path of separate segments (move to one end,
line to the other), so a frame costs a few array operations. Springs of strain also
get their level's line (`strain_style.STROKES`: thick, plain or thin dashed), one
width and dash per path. In 3-D axes the ends are projected at each draw, as
`mpl_toolkits.mplot3d`'s own collections do.
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import Collection, LineCollection
from matplotlib.path import Path
from mpl_toolkits.mplot3d import proj3d

from .strain_style import STROKES, linestyle, stroke_classes

LEVELS = 64  # colours of the scale: steps of 1/64 of its range are not visible


class SpringLines(LineCollection):
    """Springs with ends ``ends`` (E, 2, 2) coloured by ``values`` (E,) on ``cmap`` / ``norm``.

    ``values`` are shown at the middle of their level (of ``LEVELS`` across the
    norm's range; values outside it at the ends). ``ends`` and ``values`` are
    the springs' own data; ``get_array()`` holds the levels' values. With
    ``stroke_width`` (points) the values are strains, each level drawn in its
    `strain_style` stroke of that plain width.
    """

    _paths_made = True  # until the first springs are set

    def __init__(
        self,
        ends: np.ndarray,
        values: np.ndarray,
        stroke_width: float | None = None,
        **style: object,
    ) -> None:
        super().__init__([], **style)
        self.stroke_width = stroke_width
        self.set_springs(ends, values)

    def set_springs(self, ends: np.ndarray, values: np.ndarray) -> None:
        """New ends (E, 2, d) and values (E,)."""
        self.ends, self.values = np.asarray(ends, dtype=float), np.asarray(values, dtype=float)
        self._sort_into_levels()
        self._set_points(self.ends[self._order])

    def _sort_into_levels(self) -> None:
        """The springs' order by colour level and where each level present starts in it."""
        fraction = np.ma.filled(self.norm(self.values), 0.5)
        level = np.clip((fraction * LEVELS).astype(int), 0, LEVELS - 1)
        self._order = np.argsort(level, kind="stable")
        counts = np.bincount(level, minlength=LEVELS)
        present = np.flatnonzero(counts)
        self._starts = np.concatenate([[0], np.cumsum(counts[present])])
        self.set_array(self.norm.inverse((present + 0.5) / LEVELS))
        if self.stroke_width is not None:
            self._set_strokes(present)

    def _set_strokes(self, present: np.ndarray) -> None:
        """Each present level's path in its class's width and dash."""
        strokes = [STROKES[c] for c in stroke_classes(present, LEVELS)]
        self.set_linewidth([s.width * self.stroke_width for s in strokes] or [self.stroke_width])
        self.set_linestyle([linestyle(s) for s in strokes] or ["solid"])

    def _set_points(self, ends_2d: np.ndarray) -> None:
        """The ends (E, 2, 2) in level order, drawn at the next draw."""
        self._points = np.asarray(ends_2d, dtype=float).reshape(-1, 2, 2)
        self._paths_made = False
        self.stale = True

    def get_paths(self) -> list[Path]:
        """One path per colour level present, holding its springs' segments."""
        if not self._paths_made:
            points = self._points.reshape(-1, 2)
            codes = np.tile([Path.MOVETO, Path.LINETO], len(self._points)).astype(Path.code_type)
            paths = [
                Path(points[2 * start : 2 * stop], codes[2 * start : 2 * stop])
                for start, stop in zip(self._starts[:-1], self._starts[1:])
            ]
            Collection.set_paths(self, paths)  # LineCollection's own takes plain segments
            self._paths_made = True
        return super().get_paths()


class SpringLines3D(SpringLines):
    """`SpringLines` in 3-D axes: the ends (E, 2, 3) are projected when the axes draw."""

    def set_springs(self, ends: np.ndarray, values: np.ndarray) -> None:
        """New ends (E, 2, 3) and values (E,), drawn at the next projection."""
        self.ends, self.values = np.asarray(ends, dtype=float), np.asarray(values, dtype=float)
        self._sort_into_levels()
        self._set_points(np.zeros((len(self.ends), 2, 2)))  # until projected

    def do_3d_projection(self) -> float:
        """Project the ends onto the axes (3-D axes call this before drawing); return the
        smallest depth, by which the axes order their collections."""
        x, y, depth = proj3d.proj_transform(*self.ends[self._order].reshape(-1, 3).T, self.axes.M)
        self._set_points(np.stack([x, y], axis=1))
        return float(np.min(depth, initial=1e9))
