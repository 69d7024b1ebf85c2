"""Animations of a recorded `Trajectory`, saved as GIF, MP4 or an offline HTML player.

Frames are drawn once on a still background (blitting: only the body and the
title are redrawn) and kept as palette images sharing one palette of 255
colours, made from five frames spread over the animation, so a 100-frame
animation saves in about two seconds and stays small. GIF needs pillow (a
dependency), MP4 needs ffmpeg on the PATH. An .html file is a replay page
holding the positions, drawn by the live view's front end (`replay`); `to_html`
(inline in Jupyter) is a player of PNG frames with play, step and a slider.
Neither needs an external address.
"""

from __future__ import annotations

import base64
import html
import io
import uuid
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.animation import FFMpegWriter, FuncAnimation
from matplotlib.artist import Artist
from matplotlib.figure import Figure
from PIL import Image

from .. import Trajectory
from .plot_words import run_in_words
from .replay import replay_page
from .upright import resolve_up
from .view import BodyView, check_colour, new_axes, rim_height, sags, strains

FORMATS = (".gif", ".mp4", ".html")
PALETTE_COLOURS = 255  # of the frames' shared palette (GIF's 256 less one for transparency)
PALETTE_SAMPLES = 5  # frames the palette is made from


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


def strain_scale(body, frames: np.ndarray, floor: float = 0.05) -> float:
    """The strain drawn at full colour for ``frames`` (F, N, d): the 99th percentile of
    |strain| over ten sampled frames, at least ``floor`` so a body at rest stays pale."""
    if not body.n_springs:
        return floor
    sample, edges = frames[:: max(1, len(frames) // 10)], body.edges()
    return max(floor, float(max(np.percentile(np.abs(strains(edges, f)), 99) for f in sample)))


def sag_scale(body, frames: np.ndarray, up: str) -> float:
    """The sag drawn at full colour for ``frames`` (F, N, 3): 15 % of the body's size, or the
    deepest sag below the rim of the first frame if deeper, so runs of one scene share a scale."""
    rim, edges = rim_height(body, frames[0], up), body.edges()
    size = float(np.max(np.ptp(frames[0], axis=0)))
    return max(0.15 * size, float(max(sags(edges, f, up, rim).max(initial=0) for f in frames)))


@dataclass
class _Movie:
    """A figure with a drawn body and ``draw(i)``, which sets it to frame ``i``."""

    figure: Figure
    count: int
    fps: float
    draw: object  # Callable[[int], list[Artist]]

    def images(self, dpi: float) -> Iterator[Image.Image]:
        """Each frame as a palette image, drawn by blitting onto the still background.

        All frames share one palette, made from a few frames spread over the
        animation (drawn first and kept), so a colour that shows up late has its own.
        """
        self.figure.set_dpi(dpi)
        canvas = self.figure.canvas
        changing: list[Artist] = self.draw(0)
        for artist in changing:
            artist.set_animated(True)
        canvas.draw()  # the background: axes, ticks, colour bar
        background = canvas.copy_from_bbox(self.figure.bbox)

        def rgb(i: int) -> Image.Image:
            canvas.restore_region(background)
            for artist in self.draw(i):
                artist.set_animated(True)
                if hasattr(artist, "do_3d_projection"):  # what Axes3D.draw would do
                    artist.do_3d_projection()
                self.figure.draw_artist(artist)
            return Image.fromarray(np.asarray(canvas.buffer_rgba())).convert("RGB")

        picks = np.linspace(0, self.count - 1, min(self.count, PALETTE_SAMPLES)).astype(int)
        samples = {int(i): rgb(int(i)) for i in np.unique(picks)}
        palette = shared_palette(list(samples.values()))
        for i in range(self.count):
            image = samples.pop(i) if i in samples else rgb(i)
            yield image.quantize(palette=palette, dither=Image.Dither.NONE)


def shared_palette(images: Sequence[Image.Image]) -> Image.Image:
    """A palette image of ``PALETTE_COLOURS`` colours for all of ``images`` (RGB, same width)."""
    stack = np.concatenate([np.asarray(image) for image in images])
    return Image.fromarray(stack).quantize(PALETTE_COLOURS, Image.Quantize.FASTOCTREE)


def animate(
    trajectory: Trajectory,
    *,
    max_frames: int = 60,
    fps: float = 15.0,
    view: Sequence[float] | None = None,
    up: str | None = None,
    time_unit: str = "s",
    energy_unit: str = "J",
    title: str = "",
    spheres: Sequence[tuple[int, float]] = (),
    colour: str = "strain",
) -> FuncAnimation:
    """A matplotlib animation of at most ``max_frames`` evenly spaced frames of ``trajectory``.

    ``view`` (azimuth, elevation), ``up``, ``spheres`` and ``colour`` ("strain" or
    "sag") are as in `BodyView`.
    """
    movie = _build(
        trajectory, max_frames, fps, view, up, time_unit, energy_unit, title, spheres, colour
    )
    return FuncAnimation(movie.figure, movie.draw, frames=movie.count, interval=1000.0 / fps)


def to_html(
    trajectory: Trajectory,
    *,
    max_frames: int = 60,
    fps: float = 15.0,
    view: Sequence[float] | None = None,
    up: str | None = None,
    time_unit: str = "s",
    energy_unit: str = "J",
    title: str = "",
    spheres: Sequence[tuple[int, float]] = (),
    dpi: float = 80.0,
    colour: str = "strain",
) -> str:
    """The animation of ``trajectory`` as a self-contained HTML player (works offline).

    For Jupyter: ``IPython.display.HTML(to_html(trajectory))`` (needs no ffmpeg).
    Options as in `animate`, frames drawn at ``dpi``; the figure is closed, so no
    still picture shows up as well. The run in words (`run_in_words`) is its caption.
    """
    import matplotlib.pyplot as plt

    movie = _build(
        trajectory, max_frames, fps, view, up, time_unit, energy_unit, title, spheres, colour
    )
    axis = "xyz".index(resolve_up(up, trajectory, trajectory.body.dim))
    words = run_in_words(trajectory, axis, time_unit, title or "Animation")
    try:
        return html_player([_png(image) for image in movie.images(dpi)], fps, words)
    finally:
        plt.close(movie.figure)


def save_animation(
    trajectory: Trajectory,
    path: str | Path,
    *,
    fps: float = 15.0,
    dpi: int = 80,
    max_frames: int = 60,
    view: Sequence[float] | None = None,
    up: str | None = None,
    time_unit: str = "s",
    energy_unit: str = "J",
    title: str = "",
    spheres: Sequence[tuple[int, float]] = (),
    colour: str = "strain",
) -> Path:
    """Write an animation of ``trajectory`` to ``path`` (.gif, .mp4 or .html); return the path.

    At the default ``dpi`` = 80 a frame is 640 px wide. An .html file is a replay page
    holding the positions, drawn in the browser by the live view's front end (`replay`):
    it plays, pauses, scrubs and orbits offline (``dpi`` and ``colour`` do not apply).
    """
    path = Path(path)
    suffix = check_format(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".html":
        picks = _picks(trajectory, max_frames)
        page = replay_page(
            trajectory,
            picks,
            fps=fps,
            up=resolve_up(up, trajectory, trajectory.body.dim),
            view=view,
            strain_limit=strain_scale(trajectory.body, trajectory.positions[picks]),
            spheres=spheres,
            time_unit=time_unit,
            title=title,
        )
        path.write_text(page, "utf-8")
        return path
    import matplotlib.pyplot as plt

    movie = _build(
        trajectory, max_frames, fps, view, up, time_unit, energy_unit, title, spheres, colour
    )
    try:
        if suffix == ".gif":
            first, *rest = movie.images(dpi)
            first.save(path, save_all=True, append_images=rest, duration=1000.0 / fps, loop=0)
        else:
            animation = FuncAnimation(movie.figure, movie.draw, frames=movie.count)
            animation.save(path, writer=FFMpegWriter(fps=fps), dpi=dpi)
    finally:
        plt.close(movie.figure)
    return path


def html_player(frames_png: Sequence[bytes], fps: float, words: str = "") -> str:
    """An HTML player for PNG frames: play/pause, step, a slider and the frame number,
    with the frames embedded and plain-text buttons (no fonts or scripts from the web).

    ``words`` (lines: a head, then "- " items) describe the animation: the picture's text
    alternative is their first line, and all of them are its caption.
    """
    name = f"msdlab_{uuid.uuid4().hex[:12]}"
    sources = ",\n".join(
        f'"data:image/png;base64,{base64.b64encode(png).decode()}"' for png in frames_png
    )
    last = len(frames_png) - 1
    head, *items = words.splitlines() or ["animation"]
    caption = "".join(f"<li>{html.escape(item.removeprefix('- '))}</li>" for item in items)
    return f"""<figure id="{name}" style="font-family: sans-serif; margin: 0">
<img alt="{html.escape(head)}" style="max-width: 100%"><br>
<button data-do="back" aria-label="previous frame" title="previous frame">&#9664;&#9646;</button>
<button data-do="play" aria-label="play" title="play / pause">&#9654; play</button>
<button data-do="next" aria-label="next frame" title="next frame">&#9646;&#9654;</button>
<input type="range" min="0" max="{last}" value="0" aria-label="frame"
 style="width: 50%; vertical-align: middle">
<span></span>
<figcaption>{html.escape(head)}<ul style="margin: 0">{caption}</ul></figcaption>
</figure>
<script>
(function () {{
  const frames = [{sources}];
  const root = document.getElementById("{name}");
  const image = root.querySelector("img"), slider = root.querySelector("input");
  const label = root.querySelector("span"), play = root.querySelector('[data-do="play"]');
  let index = 0, timer = null;
  function show(i) {{
    index = (i + frames.length) % frames.length;
    image.src = frames[index]; slider.value = index;
    label.textContent = "frame " + (index + 1) + " of " + frames.length;
    slider.setAttribute("aria-valuetext", label.textContent);
  }}
  function stop() {{
    clearInterval(timer); timer = null;
    play.innerHTML = "&#9654; play"; play.setAttribute("aria-label", "play");
  }}
  function start() {{
    timer = setInterval(() => show(index + 1), {1000.0 / fps:.1f});
    play.innerHTML = "&#10073;&#10073; pause"; play.setAttribute("aria-label", "pause");
  }}
  root.querySelector('[data-do="back"]').onclick = () => {{ stop(); show(index - 1); }};
  root.querySelector('[data-do="next"]').onclick = () => {{ stop(); show(index + 1); }};
  play.onclick = () => (timer ? stop() : start());
  slider.oninput = () => {{ stop(); show(Number(slider.value)); }};
  show(0);
}})();
</script>"""


def _png(image: Image.Image) -> bytes:
    """``image`` as PNG, at zlib level 4: 3 % larger than at level 6, made in 60 % of the time."""
    buffer = io.BytesIO()
    image.save(buffer, format="PNG", optimize=False, compress_level=4)
    return buffer.getvalue()


def _picks(trajectory: Trajectory, max_frames: int) -> np.ndarray:
    """At most ``max_frames`` evenly spaced frame numbers of ``trajectory``."""
    return np.unique(np.linspace(0, len(trajectory) - 1, max(1, max_frames)).astype(int))


def _build(
    trajectory: Trajectory,
    max_frames: int,
    fps: float,
    view: Sequence[float] | None,
    up: str | None,
    time_unit: str,
    energy_unit: str,
    title: str,
    spheres: Sequence[tuple[int, float]],
    colour: str,
) -> _Movie:
    check_colour(colour, trajectory.body)
    up = resolve_up(up, trajectory, trajectory.body.dim)
    picks = _picks(trajectory, max_frames)
    frames = trajectory.positions[picks]
    body = trajectory.body
    ax = new_axes(body)
    limit = sag_scale(body, frames, up) if colour == "sag" else strain_scale(body, frames)
    drawing = BodyView(
        ax,
        body,
        frames[0],
        strain_limit=limit,
        view=view,
        up=up,
        spheres=spheres,
        colour=colour,
    )
    drawing.fit(frames)
    ledger = trajectory.energies.as_arrays()
    times = trajectory.times[picks]
    energies = np.interp(times, ledger["time"], ledger["total"]) if len(ledger["time"]) else None
    label = ax.set_title(" ", loc="left")

    def draw(i: int) -> list[Artist]:
        clock = f"t = {times[i]:.3g} {time_unit}"
        energy = "" if energies is None else f"E = {energies[i]:.3g} {energy_unit}"
        label.set_text(f"{title}   {clock}   {energy}".strip())
        return [*drawing.update(frames[i]), label]

    draw(0)
    return _Movie(ax.figure, len(frames), fps, draw)
