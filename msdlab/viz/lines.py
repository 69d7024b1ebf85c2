"""Many springs drawn fast: the springs of one colour level drawn as one shape.

matplotlib's `LineCollection` makes one `Path` object per segment each time its
segments change, which for a body of thousands of springs is most of the time
of an animation frame. `SpringLines` sorts the springs into ``LEVELS`` colour
levels and draws each level as one path of separate segments (move to one end,
line to the other), so a frame costs a few array operations. On an Agg canvas
(PNG files, animations, most windows) the levels are painted by `raster.paint`,
as Agg would paint those paths but about four times faster; other renderers
(PDF, SVG) get the paths. In 3-D axes the ends are projected at each draw, as
`mpl_toolkits.mplot3d`'s own collections do.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from matplotlib.backend_bases import RendererBase
from matplotlib.backends.backend_agg import RendererAgg
from matplotlib.collections import Collection, LineCollection
from matplotlib.path import Path
from mpl_toolkits.mplot3d import proj3d

LEVELS = 64  # colours of the scale: steps of 1/64 of its range are not visible
PAINT_WIDEST = 2.0  # pixels: wider lines are left to Agg (`raster.paint` cuts ends square)


class SpringLines(LineCollection):
    """Springs with ends ``ends`` (E, 2, 2) coloured by ``values`` (E,) on ``cmap`` / ``norm``.

    ``values`` are shown at the middle of their level (of ``LEVELS`` across the
    norm's range; values outside it at the ends). ``ends`` and ``values`` are
    the springs' own data; ``get_array()`` holds the levels' values.
    """

    _paths_made = True  # until the first springs are set

    def __init__(self, ends: np.ndarray, values: np.ndarray, **style: object) -> None:
        super().__init__([], **style)
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

    def draw(self, renderer: RendererBase) -> None:
        """Paint the levels on an Agg canvas (`raster.paint`), else draw the paths."""
        paint = _painter() if self._paintable(renderer) else None
        if paint is None:
            super().draw(renderer)
            return
        self.update_scalarmappable()
        image = np.asarray(renderer.buffer_rgba())
        height = image.shape[0]
        ends = self.get_transform().transform(self._points.reshape(-1, 2)).reshape(-1, 4)
        ends[:, 1::2] = height - ends[:, 1::2]  # Agg's rows run down
        width = renderer.points_to_pixels(self.get_linewidth()[0])
        if self.get_snap() is None:
            _snap(ends, self._starts, width)
        clip = (0, 0, image.shape[1], height)
        box = self.get_clip_box() if self.get_clip_on() else None
        if box is not None:  # rounded as Agg rounds its clip box
            left, right = (int(np.floor(x + 0.5)) for x in (box.x0, box.x1))
            top, bottom = (int(np.floor(height - y + 0.5)) for y in (box.y1, box.y0))
            clip = (max(left, 0), max(top, 0), min(right, clip[2]), min(bottom, clip[3]))
        colours = np.resize(self.get_edgecolor(), (len(self._starts) - 1, 4))
        paint(image, ends, self._starts, colours, width, clip)
        self.stale = False

    def _paintable(self, renderer: RendererBase) -> bool:
        """Whether `raster.paint` draws what Agg would: plain solid lines of one width."""
        return (
            isinstance(renderer, RendererAgg)
            and self.get_visible()
            and len(self._points) > 0
            and self.get_clip_path() is None
            and self.get_agg_filter() is None
            and self.get_snap() is not True
            and not self.get_path_effects()
            and self.get_sketch_params() is None
            and self.get_hatch() is None
            and len(self.get_linewidth()) == 1
            and renderer.points_to_pixels(self.get_linewidth()[0]) <= PAINT_WIDEST
            and all(dashes is None for _, dashes in self.get_linestyle())
            and all(self.get_antialiased())
        )


def _snap(ends: np.ndarray, starts: np.ndarray, width: float) -> None:
    """Move the ends (S, 4) of each level of only horizontal and vertical segments (at most
    512) to the middles of pixels (odd ``width``, rounded) or their corners, as Agg does."""
    crooked = (np.abs(ends[:, 2:] - ends[:, :2]) >= 1e-4).all(axis=1)
    counts = np.diff(starts)
    snapped = ~np.logical_or.reduceat(crooked, starts[:-1]) & (counts <= 512)
    if snapped.any():
        rows = np.repeat(snapped, counts)
        ends[rows] = np.floor(ends[rows] + 0.5) + (0.5 if np.floor(width + 0.5) % 2 else 0.0)


_PAINT: list[Callable[..., None] | None] = []


def _painter() -> Callable[..., None] | None:
    """`raster.paint`, imported at the first use (it compiles with numba), or None if numba
    cannot be imported: then Agg draws the paths."""
    if not _PAINT:
        try:
            from .raster import paint
        except ImportError:
            paint = None
        _PAINT.append(paint)
    return _PAINT[0]


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
