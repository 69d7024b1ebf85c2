"""Ready-made scenes from the seed documents, each a function returning a `Simulation`.

One module per seed: `trampoline` (a ball on a net), `cloth` (a hanging
cloth), `gallery` (the 2-D springs page) and `jelly` (the brief's cube).
`SCENES` names them all for the command line::

    from msdlab.scenes import get_scene, trampoline
    sim = trampoline.trampoline(ball_mass=5.0)
    sim = get_scene("jelly-cube").build(size=8)
"""

from . import cloth, gallery, jelly, trampoline
from .frame_model import FrameEuler
from .registry import SCENES, Scene, get_scene

__all__ = ["SCENES", "FrameEuler", "Scene", "cloth", "gallery", "get_scene", "jelly", "trampoline"]
