"""Seeing a simulation: plots of a body and of its energy ledger, animations, mouse dragging.

from msdlab import viz
viz.plot_body(sim.body)                        # springs drawn by strain
viz.plot_energy(trajectory.energies)
viz.save_animation(trajectory, "run.gif")      # or .mp4 (needs ffmpeg), .html (a replay page)
viz.save_scene_animation(scene, sim, trajectory, "run.gif")   # a scene as the gallery draws it
HTML(viz.to_html(trajectory))                  # in Jupyter: inline, with play controls
viz.show(sim)                                  # live: drag particles (notebook or window)
"""

from .animation import FORMATS, animate, save_animation, to_html
from .energy import plot_energy
from .interactive import Dragger, show
from .scene import plot_scene, save_scene_animation, scene_options
from .view import BodyView, new_axes, plot_body, spheres_of, strains
from .widget import LiveView

__all__ = [
    "FORMATS",
    "BodyView",
    "Dragger",
    "LiveView",
    "animate",
    "new_axes",
    "plot_body",
    "plot_energy",
    "plot_scene",
    "save_animation",
    "save_scene_animation",
    "scene_options",
    "show",
    "spheres_of",
    "strains",
    "to_html",
]
