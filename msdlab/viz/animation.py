"""Animations of a recorded `Trajectory` (matplotlib `FuncAnimation`), saved as GIF, MP4 or HTML.

GIF needs pillow (a dependency), MP4 needs ffmpeg on the PATH, HTML is a
self-contained page (frames embedded, with play controls).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter
from matplotlib.figure import Figure

from ..simulation import Trajectory
from .view import BodyView, new_axes, strains

FORMATS = (".gif", ".mp4", ".html")


def check_format(path: str | Path) -> str:
    """The animation format of ``path`` (its suffix), or an error saying what is possible."""
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(
            f"cannot save an animation as {Path(path).name!r}; "
            f"use a file ending in {', '.join(FORMATS)}"
        )
    if suffix == ".mp4" and not FFMpegWriter.isAvailable():
        raise RuntimeError(
            "saving MP4 needs ffmpeg, which is not on the PATH; install it or save as .gif or .html"
        )
    return suffix


def animate(
    trajectory: Trajectory,
    *,
    max_frames: int = 100,
    fps: float = 20.0,
    view: Sequence[float] | None = None,
    up: str = "z",
    time_unit: str = "s",
    title: str = "",
    spheres: Sequence[tuple[int, float]] = (),
) -> FuncAnimation:
    """An animation of at most ``max_frames`` evenly spaced frames of ``trajectory``.

    ``view`` (azimuth, elevation), ``up`` and ``spheres`` are as in `BodyView`.
    """
    return _build(trajectory, max_frames, fps, view, up, time_unit, title, spheres)[0]


def to_html(
    trajectory: Trajectory,
    *,
    max_frames: int = 100,
    fps: float = 20.0,
    view: Sequence[float] | None = None,
    up: str = "z",
    time_unit: str = "s",
    title: str = "",
    spheres: Sequence[tuple[int, float]] = (),
    dpi: float = 72.0,
) -> str:
    """The animation of ``trajectory`` as self-contained HTML (frames embedded, play controls).

    For Jupyter: ``IPython.display.HTML(to_html(trajectory))`` (needs no ffmpeg).
    Options as in `animate`, frames drawn at ``dpi``; the figure is closed, so no
    still picture shows up as well.
    """
    import matplotlib.pyplot as plt

    animation, figure = _build(trajectory, max_frames, fps, view, up, time_unit, title, spheres)
    figure.set_dpi(dpi)
    try:
        return animation.to_jshtml(fps=fps)
    finally:
        plt.close(figure)


def _build(
    trajectory: Trajectory,
    max_frames: int,
    fps: float,
    view: Sequence[float] | None,
    up: str,
    time_unit: str,
    title: str,
    spheres: Sequence[tuple[int, float]],
) -> tuple[FuncAnimation, Figure]:
    picks = np.unique(np.linspace(0, len(trajectory) - 1, max(1, max_frames)).astype(int))
    frames = trajectory.positions[picks]
    body = trajectory.body
    sample = frames[:: max(1, len(frames) // 10)]
    limit = 1e-3  # the strain drawn at full colour
    if body.n_springs:
        limit = max(limit, float(max(np.percentile(np.abs(strains(body, f)), 99) for f in sample)))
    ax = new_axes(body, size=5.0)
    drawing = BodyView(ax, body, frames[0], strain_limit=limit, view=view, up=up, spheres=spheres)
    drawing.fit(frames)
    label = ax.set_title("")

    def draw(i: int) -> list:
        label.set_text(f"{title}  t = {trajectory.times[picks[i]]:.3g} {time_unit}".strip())
        return [*drawing.update(frames[i]), label]

    draw(0)
    animation = FuncAnimation(ax.figure, draw, frames=len(frames), interval=1000.0 / fps)
    return animation, ax.figure


def save_animation(
    trajectory: Trajectory,
    path: str | Path,
    *,
    fps: float = 20.0,
    dpi: int = 80,
    max_frames: int = 100,
    view: Sequence[float] | None = None,
    up: str = "z",
    time_unit: str = "s",
    title: str = "",
    spheres: Sequence[tuple[int, float]] = (),
) -> Path:
    """Write an animation of ``trajectory`` to ``path`` (.gif, .mp4 or .html); return the path."""
    path = Path(path)
    suffix = check_format(path)
    import matplotlib.pyplot as plt

    animation, figure = _build(trajectory, max_frames, fps, view, up, time_unit, title, spheres)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        if suffix == ".html":
            path.write_text(animation.to_jshtml(fps=fps), encoding="utf-8")
        else:
            writer = PillowWriter(fps=fps) if suffix == ".gif" else FFMpegWriter(fps=fps)
            animation.save(path, writer=writer, dpi=dpi)
    finally:
        plt.close(figure)
    return path
