"""The Warp backend: the engine's equations as NVIDIA Warp kernels, on a GPU or on Warp's CPU
device (`backend.WarpKernel`, ``kernel="warp"``).

Three files: `kernels` (the equations as Warp functions and the passes over springs and
particles, per precision), `update` (an integrator's update typed for Warp and its particle
pass), `backend` (the contract's methods, the state on the device, a whole step there).
Warp is an optional dependency (``pip install "msdlab[warp]"``); this package imports it.
"""

from .backend import Ground, StepSums, WarpKernel

__all__ = ["Ground", "StepSums", "WarpKernel"]
