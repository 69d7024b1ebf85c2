"""Pictures in words: what a plot or an animation shows, in numbers.

A text alternative (WCAG 1.1.1) read from the same data the picture draws: the lines of a
matplotlib plot, the frames of a run. `to_html`'s player carries its run's words as the
picture's caption; a notebook prints a plot's words under it::

    plt.show()
    print(viz.plot_in_words(ax))  # "Cost of a step: ms per step against springs. ..."
    viz.run_in_words(run)         # "Animation of 41 frames, t = 0 to 100: ..."
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from .view import strains


def number(value: float) -> str:
    """``value`` to three significant figures, without an exponent from 0.001 to 999 999;
    a whole number as it is (a step, a count)."""
    value = float(value)
    if not math.isfinite(value):
        return "not a number" if math.isnan(value) else f"{'-' if value < 0 else ''}infinite"
    if not value.is_integer():
        value = float(f"{value:.3g}")  # 0.99996 is 1, as said
    if value == 0:
        return "0"
    magnitude = math.floor(math.log10(abs(value)))
    if value.is_integer() and magnitude < 6:
        return str(int(value))
    if -3 <= magnitude < 6:
        return f"{value + 0.0:.{max(0, 2 - magnitude)}f}"
    return f"{value:.2e}"


def curve_in_words(name: str, x: np.ndarray, y: np.ndarray, x_label: str, y_label: str = "") -> str:
    """One line of a plot: where it starts and ends, its lowest and highest points; the
    axes' labels ``x_label`` and ``y_label`` give the numbers their units ('time (s)')."""
    x, y = np.asarray(x, dtype=float).ravel(), np.asarray(y, dtype=float).ravel()
    shown = np.isfinite(y)
    if not shown.any():
        return f"{name}: no finite values"
    x, y = x[shown], y[shown]
    (x_name, x_unit), (_, y_unit) = named(x_label), named(y_label)

    def at(i: int) -> str:
        return f"{number(y[i])}{y_unit} at {x_name} = {number(x[i])}{x_unit}"

    low, high = int(np.argmin(y)), int(np.argmax(y))
    if number(y[low]) == number(y[high]):  # level, to the figures said
        return f"{name}: level at {number(y[low])}{y_unit}"
    return f"{name}: from {at(0)} to {at(-1)}; lowest {at(low)}, highest {at(high)}"


def named(label: str) -> tuple[str, str]:
    """An axis label's name and its unit (with its space): 'time (s)' -> ('time', ' s')."""
    found = re.fullmatch(r"(.*\S)\s*\(([^()]+)\)", label)
    return (found[1], f" {found[2]}") if found else (label, "")


def plot_in_words(ax: Any) -> str:
    """The lines of a matplotlib Axes in words: its title, axes and each line's numbers; of
    a Figure, those of each of its Axes that has lines.

    A line without a legend label (such as a floor drawn with ``axhline``) is "a line".
    """
    if hasattr(ax, "get_axes"):  # a Figure
        return "\n".join(plot_in_words(each) for each in ax.get_axes() if each.get_lines())
    x_label, y_label = ax.get_xlabel() or "x", ax.get_ylabel() or "y"
    title = ax.get_title()
    lines = ax.get_lines()
    head = f"{title + ': ' if title else ''}{y_label} against {x_label}, {len(lines)} line(s)."
    described = [
        curve_in_words(
            "a line" if line.get_label().startswith("_") else line.get_label(),
            line.get_xdata(),
            line.get_ydata(),
            x_label,
            y_label,
        )
        for line in lines
    ]
    return "\n".join([head, *(f"- {words}" for words in described)])


def run_in_words(run: Any, up: int = 1, time_unit: str = "", title: str = "Animation") -> str:
    """An animation of ``run`` (a `msdlab.Trajectory`) in words: over its frames, the height
    (coordinate ``up``) of the lowest particle and of the body (highest minus lowest)."""
    heights = np.asarray(run.positions, dtype=float)[..., up]
    times = np.asarray(run.times, dtype=float)
    t = f"t ({time_unit})" if time_unit else "t"
    _, unit = named(t)
    return "\n".join(
        [
            f"{title} of {len(times)} frames, t = {number(times[0])} to {number(times[-1])}{unit}:",
            "- " + curve_in_words("lowest particle's height", times, heights.min(axis=1), t),
            "- " + curve_in_words("height of the body", times, np.ptp(heights, axis=1), t),
        ]
    )


def body_in_words(body: Any, positions: Any = None, up: int = 1, title: str = "") -> str:
    """A picture of ``body`` (a `msdlab.Body`, at ``positions``, default its own) in words:
    its particles and springs, its size along each axis, its lowest point (along coordinate
    ``up``) and the strain of its springs (`strains`: negative squeezed, positive stretched)."""
    x = np.asarray(body.positions if positions is None else positions, dtype=float)
    axes = "xyz"[: x.shape[1]]
    size = " by ".join(f"{number(extent)} along {axis}" for extent, axis in zip(np.ptp(x, 0), axes))
    words = (
        f"{title + ': ' if title else ''}a body of {body.n_particles} particles and "
        f"{body.n_springs} springs, {size}; its lowest point at {axes[up]} = "
        f"{number(x[:, up].min())}"
    )
    if not body.n_springs:
        return words
    strain = strains(body.edges(), x)
    return f"{words}; its springs' strain from {strain.min():+.2%} to {strain.max():+.2%}"
