"""What the browser's drawing (``live.js``) needs to know of a scene, as JSON and arrays.

The body's springs (int32 pairs), rest lengths (float32) and pinned particles
(uint8) go once; positions (float32) go every frame. The scene dict holds the
colour table of the springs (`strain_style.STRAIN_MAP` in `LEVELS` levels, as the
animations draw them) with each level's line and the key in words, the vertical
axis, the initial camera and the walls and floor as line segments.
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import product
from pathlib import Path

import numpy as np
from matplotlib.colors import to_hex

from .. import Body, Simulation
from ..interaction import Ground, Walls
from .lines import LEVELS
from .strain_style import STRAIN_MAP, scene_strokes
from .upright import UPS

ESM = Path(__file__).with_name("live.js")  # the front end, an ES module (package data)
SIZE = (640, 480)  # the body's canvas (px)
SPRING_WIDTH = 1.5  # px: a spring near its rest length (see `strain_style.STROKES`)


def colour_table() -> list[str]:
    """The springs' colours, squeezed (blue) to stretched (orange), one per level."""
    return [to_hex(STRAIN_MAP((level + 0.5) / LEVELS)) for level in range(LEVELS)]


def body_arrays(body: Body) -> dict[str, bytes]:
    """The body's fixed arrays as bytes: springs (int32 pairs), rest lengths, pinned."""
    edges = body.edges()
    pairs = np.column_stack([edges.a, edges.b]).astype(np.int32)
    return {
        "springs": pairs.tobytes(),
        "rest": edges.rest_lengths.astype(np.float32).tobytes(),
        "fixed": body.fixed.astype(np.uint8).tobytes(),
    }


def box_edges(lower: np.ndarray, upper: np.ndarray) -> list[list[list[float]]]:
    """The edges of the box [lower, upper] (2-D: 4, 3-D: 12) as pairs of corners."""
    dim = len(lower)
    corners = [np.where(np.array(bits) == 1, upper, lower) for bits in product((0, 1), repeat=dim)]
    return [
        [a.tolist(), b.tolist()]
        for i, a in enumerate(corners)
        for b in corners[i + 1 :]
        if np.count_nonzero(a != b) == 1
    ]


def floor_edges(
    normal: np.ndarray, height: float, low: np.ndarray, high: np.ndarray, lines: int = 9
) -> list[list[list[float]]]:
    """A grid of ``lines`` × ``lines`` lines on the floor plane under the box [low, high]."""
    axis = int(np.argmax(np.abs(normal)))
    others = [k for k in range(len(normal)) if k != axis]
    edges = []
    for k, across in zip(others, others[::-1]):
        for value in np.linspace(low[k], high[k], lines if len(normal) == 3 else 2):
            a, b = np.zeros(len(normal)), np.zeros(len(normal))
            a[k] = b[k] = value
            a[across], b[across] = low[across], high[across]
            a[axis] = b[axis] = height / normal[axis]
            edges.append([a.tolist(), b.tolist()])
    return edges if len(normal) == 3 else [[edges[0][0], edges[-1][1]]]


def world_of(sim: Simulation, low: np.ndarray, high: np.ndarray) -> list:
    """Line segments of the walls and floor of ``sim`` around the body's box [low, high]."""
    edges: list = []
    for item in sim.constraints:
        if isinstance(item, Walls):
            lower = np.where(np.isfinite(item.lower), item.lower, low)
            upper = np.where(np.isfinite(item.upper), item.upper, high)
            edges += box_edges(lower, upper)
        elif isinstance(item, Ground):
            edges += floor_edges(item.normal_of(sim.body), item.height, low, high)
    return edges


def describe(
    sim: Simulation,
    *,
    up: str,
    view: Sequence[float] | None,
    strain_limit: float,
    spheres: Sequence[tuple[int, float]] = (),
    energy_unit: str | None = None,
    energy: bool = True,
) -> dict:
    """The scene dict of ``sim`` for ``live.js``: camera, colours, walls, floor, balls, and
    the units of time and energy (``energy_unit``, default the simulation's, `sim.units`)."""
    positions = sim.body.positions
    low, high = positions.min(axis=0), positions.max(axis=0)
    middle, reach = 0.5 * (low + high), 0.75 * max(float(np.max(high - low)), 1e-9)
    around_low, around_high = middle - reach, middle + reach  # room to fall and swing
    world = world_of(sim, around_low, around_high)
    points = np.array([p for edge in world for p in edge] or positions[:1])
    box_low = np.minimum(around_low, points.min(axis=0))
    box_high = np.maximum(around_high, points.max(axis=0))
    return {
        "dim": sim.body.dim,
        "up": UPS.index(up),
        "view": list(view or (45.0, 30.0)),
        "centre": (0.5 * (box_low + box_high)).tolist(),
        "span": float(np.max(box_high - box_low)),
        "strain_limit": float(strain_limit),
        "colours": colour_table(),
        **scene_strokes(SPRING_WIDTH, LEVELS),
        "world": {"edges": world},
        "spheres": [[int(p), float(r)] for p, r in spheres],
        "energy": energy,
        "energy_unit": energy_unit or sim.units.energy,
        "time_unit": sim.units.time,
        "length_unit": sim.units.length,
        "width": SIZE[0],
        "height": SIZE[1],
    }
