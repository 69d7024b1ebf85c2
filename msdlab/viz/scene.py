"""A scene drawn as the gallery and ``msdlab run`` draw it: its view, vertical axis,
spheres, spring colouring, time unit and title, with no options to repeat."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from .. import Simulation, Trajectory
from ..scenes.registry import Scene
from .animation import save_animation
from .view import plot_body, spheres_of


def scene_options(scene: Scene, sim: Simulation) -> dict[str, Any]:
    """How ``scene`` is drawn: view, up axis, the spheres of ``sim``, spring colour, title."""
    return {
        "view": scene.view,
        "up": scene.up,
        "spheres": spheres_of(sim),
        "colour": scene.colour,
        "title": scene.name,
    }


def plot_scene(scene: Scene, sim: Simulation, **options: Any) -> Figure:
    """`plot_body` of ``sim``'s body as ``scene`` is drawn (``options`` override)."""
    return plot_body(sim.body, **{**scene_options(scene, sim), **options})


def save_scene_animation(
    scene: Scene, sim: Simulation, run: Trajectory, path: str | Path, **options: Any
) -> Path:
    """`save_animation` of ``run`` (a run of ``sim``) as ``scene`` is drawn, with its units
    of time and energy and number of frames (``options`` override)."""
    drawn = {
        **scene_options(scene, sim),
        "time_unit": scene.unit,
        "energy_unit": scene.energy_unit,
        "max_frames": scene.frames,
    }
    return save_animation(run, path, **{**drawn, **options})
