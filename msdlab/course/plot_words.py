"""The course notebooks' pictures in words: what a plot or an animation shows, in numbers.

A text alternative (WCAG 1.1.1) printed under a picture, read from the same data the
picture draws: the lines of a matplotlib plot, the frames of a run::

    plt.show()
    print(plot_in_words(ax))  # "Cost of a step: ms per step against springs. ..."
    print(run_in_words(run))  # "Animation of 41 frames, t = 0 to 100: ..."
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def number(value: float) -> str:
    """``value`` to three significant figures, without an exponent from 0.001 to 999 999;
    a whole number as it is (a step, a count)."""
    value = float(value)
    if not math.isfinite(value):
        return "not a number" if math.isnan(value) else f"{'-' if value < 0 else ''}infinite"
    if value == 0:
        return "0"
    magnitude = math.floor(math.log10(abs(value)))
    if value.is_integer() and magnitude < 6:
        return str(int(value))
    if -3 <= magnitude < 6:
        return f"{value + 0.0:.{max(0, 2 - magnitude)}f}"
    return f"{value:.2e}"


def curve_in_words(name: str, x: np.ndarray, y: np.ndarray, x_name: str) -> str:
    """One line of a plot: where it starts and ends, its lowest and highest points."""
    x, y = np.asarray(x, dtype=float).ravel(), np.asarray(y, dtype=float).ravel()
    shown = np.isfinite(y)
    if not shown.any():
        return f"{name}: no finite values"
    if np.ptp(y[shown]) == 0:
        return f"{name}: level at {number(y[shown][0])}"
    x, y = x[shown], y[shown]
    low, high = int(np.argmin(y)), int(np.argmax(y))
    return (
        f"{name}: from {number(y[0])} at {x_name} = {number(x[0])} to {number(y[-1])} at "
        f"{x_name} = {number(x[-1])}; lowest {number(y[low])} at {x_name} = {number(x[low])}, "
        f"highest {number(y[high])} at {x_name} = {number(x[high])}"
    )


def plot_in_words(ax: Any) -> str:
    """The lines of a matplotlib Axes in words: its title, axes and each line's numbers.

    A line without a legend label (such as a floor drawn with ``axhline``) is "a line".
    """
    x_name, y_name = ax.get_xlabel() or "x", ax.get_ylabel() or "y"
    title = ax.get_title()
    lines = ax.get_lines()
    head = f"{title + ': ' if title else ''}{y_name} against {x_name}, {len(lines)} line(s)."
    described = [
        curve_in_words(
            "a line" if line.get_label().startswith("_") else line.get_label(),
            line.get_xdata(),
            line.get_ydata(),
            x_name,
        )
        for line in lines
    ]
    return "\n".join([head, *(f"- {words}" for words in described)])


def run_in_words(run: Any, up: int = 1, time_unit: str = "", title: str = "Animation") -> str:
    """An animation of ``run`` (a `msdlab.Trajectory`) in words: over its frames, the height
    (coordinate ``up``) of the lowest particle and of the body (highest minus lowest)."""
    heights = np.asarray(run.positions, dtype=float)[..., up]
    times = np.asarray(run.times, dtype=float)
    unit = f" {time_unit}" if time_unit else ""
    return "\n".join(
        [
            f"{title} of {len(times)} frames, t = {number(times[0])} to {number(times[-1])}{unit}:",
            "- " + curve_in_words("lowest particle's height", times, heights.min(axis=1), "t"),
            "- " + curve_in_words("height of the body", times, np.ptp(heights, axis=1), "t"),
        ]
    )
