"""Seeing a simulation: plots of a body and of its energy ledger, animations, mouse dragging.

from msdlab import viz
viz.plot_body(sim.body)                        # springs drawn by strain
viz.plot_energy(trajectory.energies)
print(viz.plot_in_words(ax))                   # a plot's lines in words (the Axes drawn on)
viz.save_animation(trajectory, "run.gif")      # or .mp4 (needs ffmpeg), .html (a replay page)
viz.save_scene_animation(scene, sim, trajectory, "run.gif")   # a scene as the gallery draws it
HTML(viz.to_html(trajectory))                  # in Jupyter: inline, with play controls
viz.show(sim)                                  # live: drag particles (notebook or window)
"""

from .animation import FORMATS, animate, save_animation, to_html
from .energy import plot_energy
from .interactive import Dragger, show
from .plot_words import body_in_words, plot_in_words, run_in_words
from .scene import plot_scene, save_scene_animation, scene_options
from .view import BodyView, new_axes, plot_body, spheres_of, strains
from .widget import LiveView

__all__ = [
    "FORMATS",
    "BodyView",
    "Dragger",
    "LiveView",
    "animate",
    "body_in_words",
    "new_axes",
    "plot_body",
    "plot_energy",
    "plot_in_words",
    "plot_scene",
    "run_in_words",
    "save_animation",
    "save_scene_animation",
    "scene_options",
    "show",
    "spheres_of",
    "strains",
    "to_html",
]
