"""How long does saving a 100-frame animation take, as GIF and as HTML?

Two scenes, recorded once, then saved with `viz.save_animation` at its
defaults (640 px wide, ``dpi=80``) into a temporary folder:

- cube: the ``msdlab demo`` jelly cube (``jelly-cube`` scene, its view and
  vertical axis) at 8³ particles (5,068 springs), 1,200 steps recorded every
  10th, 100 frames shown;
- rope: the gallery's 2-D ``rope`` (18 particles), 600 frames recorded every
  5th, 100 frames shown.

A save is timed in CPU seconds of this process (``time.process_time``: the
machine is shared, wall time counts the other programs), the whole call:
building the figure, drawing each frame, encoding, writing. Each (scene,
format) is saved ``--repeats`` times after a first save (which also loads
fonts and compiled code), and the table shows the median and the range, the
first save and the file's size.

    python benchmarks/animation_save.py                  # both scenes, GIF and HTML
    python benchmarks/animation_save.py --repeats 5 --scenes cube --formats .gif
    python benchmarks/animation_save.py --profile 25     # where the time goes (cProfile)
    python benchmarks/animation_save.py --frames-to DIR  # frames 0, 50, 99 as PNG, to look at

``--profile N`` saves each (scene, format) once more under cProfile and
prints the seconds spent in the parts of a save (cumulative, so a part may
hold another: the background holds text too) and the N functions with the
most time inside them (cProfile's own overhead inflates all of them).
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np

from msdlab import Trajectory, viz
from msdlab.scenes import get_scene

FRAMES = 100
FORMATS = (".gif", ".html")


def cube_run(size: int = 8) -> tuple[Trajectory, dict]:
    """The demo's jelly cube at ``size``³, 1,200 steps, and the demo's animation options."""
    scene = get_scene("jelly-cube")
    trajectory = scene.build(size=size).run(steps=1200, record_every=10)
    options = {"view": scene.view, "up": scene.up, "time_unit": scene.unit, "title": "jelly cube"}
    return trajectory, options


def rope_run() -> tuple[Trajectory, dict]:
    """The gallery's rope, 600 frames of its clock, and the options `msdlab run` uses."""
    scene = get_scene("rope")
    trajectory = scene.build().run(steps=600, record_every=5)
    return trajectory, {"time_unit": scene.unit, "title": scene.name}


SCENES = {"cube": cube_run, "rope": rope_run}


def save_seconds(trajectory: Trajectory, path: Path, options: dict) -> float:
    """CPU seconds of one `save_animation` of ``FRAMES`` frames to ``path``."""
    start = time.process_time()
    viz.save_animation(trajectory, path, max_frames=FRAMES, **options)
    return time.process_time() - start


# The parts of a save: (what, file the function is in, function name).
PARTS = [
    ("the figure, colour bar, limits", "viz/animation.py", "_build"),
    ("background: axes, ticks (once)", "backends/backend_agg.py", "draw"),
    ("body update: strains, levels", "viz/view.py", "update"),
    ("3-D projection of the springs", "viz/lines.py", "do_3d_projection"),
    ("springs drawn (Agg)", "collections.py", "draw"),
    ("dots (Line2D, Line3D)", "matplotlib/lines.py", "draw"),
    ("text (title; ticks once)", "matplotlib/text.py", "draw"),
    ("frame from the canvas to RGB", "PIL/Image.py", "convert"),
    ("palette: quantising", "PIL/Image.py", "quantize"),
    ("GIF encoding and writing", "PIL/GifImagePlugin.py", "_save_all"),
    ("PNG encoding (HTML)", "viz/animation.py", "_png"),
    ("HTML player: base64, text", "viz/animation.py", "html_player"),
]


def profile(trajectory: Trajectory, path: Path, options: dict, top: int) -> None:
    """One save under cProfile: seconds in each of `PARTS`, then the ``top`` functions by
    their own time."""
    profiler = cProfile.Profile()
    profiler.enable()
    viz.save_animation(trajectory, path, max_frames=FRAMES, **options)
    profiler.disable()
    stats = pstats.Stats(profiler)
    total = max(entry[3] for entry in stats.stats.values())
    print(f"\n{path.name} under cProfile: {total:.2f} s")
    for what, where, function in PARTS:
        seconds = sum(
            entry[3]
            for (file, _, name), entry in stats.stats.items()
            if name == function and file.replace(os.sep, "/").endswith(where)
        )
        print(f"  {what:32s} {seconds:6.2f} s  {100 * seconds / total:3.0f} %")
    stats.strip_dirs().sort_stats("tottime").print_stats(top)


def write_frames(trajectory: Trajectory, folder: Path, name: str, options: dict) -> None:
    """Frames 0, 50 and 99 of the GIF as PNG files in ``folder``, to compare by eye."""
    from PIL import Image

    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as scratch:
        gif = viz.save_animation(trajectory, Path(scratch) / "a.gif", max_frames=FRAMES, **options)
        with Image.open(gif) as image:
            for index in (0, FRAMES // 2, FRAMES - 1):
                image.seek(index)
                image.convert("RGB").save(folder / f"{name}_{index:03d}.png")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", nargs="+", choices=list(SCENES), default=list(SCENES))
    parser.add_argument("--formats", nargs="+", choices=FORMATS, default=list(FORMATS))
    parser.add_argument("--repeats", type=int, default=3, help="timed saves per row")
    parser.add_argument("--size", type=int, default=8, help="particles per cube edge")
    parser.add_argument("--profile", type=int, metavar="N", help="print cProfile's top N")
    parser.add_argument("--frames-to", type=Path, metavar="DIR", help="write frames as PNG")
    args = parser.parse_args()

    print(f"{FRAMES} frames at dpi 80; load average {os.getloadavg()[0]:.2f}")
    print("| scene | format | CPU s, median (range) | first save | size kB |")
    print("| --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as folder:
        for name in args.scenes:
            trajectory, options = cube_run(args.size) if name == "cube" else SCENES[name]()
            if args.frames_to is not None:
                write_frames(trajectory, args.frames_to, name, options)
            for suffix in args.formats:
                path = Path(folder) / f"{name}{suffix}"
                first = save_seconds(trajectory, path, options)
                times = [save_seconds(trajectory, path, options) for _ in range(args.repeats)]
                size = path.stat().st_size / 1e3
                median = float(np.median(times))
                print(
                    f"| {name} | {suffix} | {median:.2f} ({min(times):.2f}–{max(times):.2f}) "
                    f"| {first:.2f} | {size:.0f} |",
                    flush=True,
                )
                if args.profile:
                    profile(trajectory, path, options, args.profile)
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
