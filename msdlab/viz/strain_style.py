"""How a spring's strain is drawn: a colour and a line, so that it reads without colour.

Colour: `STRAIN_MAP`, a diverging map from dark blue (squeezed) through mid grey (at
rest) to dark orange (stretched). Every colour has at least 4:1 contrast against white
(WCAG 1.4.11 asks 3:1 of a line that carries meaning), each gets darker the farther it is
from rest, and the two ends stay apart with red-green and blue-yellow colour blindness.
Line: `STROKES`, three classes told at a glance, the same in the pictures, the live view
and the replay page: squeezed springs thin and dashed, those near their rest length plain,
stretched ones thick. `KEY` says all of it in words.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.colors import LinearSegmentedColormap, to_hex
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

STRAIN_MAP = LinearSegmentedColormap.from_list("msdlab-strain", ["#1f4e99", "#7f7f7f", "#a33d05"])
NEAR_REST = 0.25  # |strain| below this share of the scale's limit is drawn as at rest


@dataclass(frozen=True)
class Stroke:
    """A class of springs' line: ``width`` times the plain width, ``dash`` (on, off) in
    line widths, or None for a solid line; ``end`` the map's colour the key shows."""

    name: str
    width: float
    dash: tuple[float, float] | None
    end: float


STROKES = (
    Stroke("squeezed", 0.75, (3.0, 2.0), 0.0),
    Stroke("near rest length", 1.0, None, 0.5),
    Stroke("stretched", 2.0, None, 1.0),
)
KEY = (
    "Springs: thick orange stretched, plain grey near their rest length, "
    "thin dashed blue squeezed; the deeper the colour, the larger the strain."
)


def stroke_classes(levels: np.ndarray, count: int) -> np.ndarray:
    """The class (index into `STROKES`) of colour levels ``levels`` of ``count`` across
    the map: the middle `NEAR_REST` of the map is at rest."""
    fraction = (np.asarray(levels) + 0.5) / count - 0.5  # -0.5 to 0.5, 0 at rest
    return np.where(fraction < -NEAR_REST / 2, 0, np.where(fraction > NEAR_REST / 2, 2, 1))


def linestyle(stroke: Stroke) -> str | tuple[float, tuple[float, float]]:
    """``stroke``'s matplotlib line style (matplotlib scales dashes by the line width)."""
    return "solid" if stroke.dash is None else (0.0, stroke.dash)


def add_key(figure: Figure, width: float) -> None:
    """The key to the lines on ``figure``, for springs of plain width ``width`` (points):
    under everything, or above the title of a figure without a layout engine (a window's,
    whose axes stay still), where nothing would make room for it below."""
    handles = [
        Line2D(
            [],
            [],
            color=STRAIN_MAP(stroke.end),
            linewidth=stroke.width * width,
            linestyle=linestyle(stroke),
            label=stroke.name,
        )
        for stroke in reversed(STROKES)
    ]
    fixed = figure.get_layout_engine() is None
    figure.legend(
        handles=handles,
        loc="upper center" if fixed else "outside lower center",
        ncols=3,
        fontsize="small",
        frameon=False,
        title="springs",
        title_fontsize="small",
    )


def scene_strokes(width: float, count: int) -> dict:
    """The strokes for ``live.js``: per class its name, width (px), dash (px, [] for solid)
    and key colour, the class of each of ``count`` colour levels, and the key in words."""
    return {
        "strokes": [
            {
                "name": stroke.name,
                "width": stroke.width * width,
                "dash": [d * stroke.width * width for d in stroke.dash or ()],
                "colour": to_hex(STRAIN_MAP(stroke.end)),
            }
            for stroke in STROKES
        ],
        "stroke_of_level": stroke_classes(np.arange(count), count).tolist(),
        "key": KEY,
    }
