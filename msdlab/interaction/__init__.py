"""Scene-level interaction: the ground, drag, walls, driven and grabbed particles, ball contact.

Built on the engine (`msdlab.engine.model.constraint`, `msdlab.engine.model.forces`);
re-exported from `msdlab`.
"""

from .constraints import Drag, Grab, Ground, Prescribed, Walls
from .contact import SphereContact

__all__ = ["Drag", "Grab", "Ground", "Prescribed", "SphereContact", "Walls"]
