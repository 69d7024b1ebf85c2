"""Analysis on top of the engine: the predicted stable time step and the diagnosis
of a blow-up, measured blow-up time steps, convergence orders, and running the
calls of sweeps and grading side by side, here or on a Dask cluster (`cluster`).

The predictions and measurements are re-exported from `msdlab`.
"""

from ..engine.simulation.stability import Mode, max_stable_dt, stability_limit, stiffest_mode
from .measure import Convergence, bisect_blowup, convergence_order, measure_blowup_dt

__all__ = [
    "Convergence",
    "Mode",
    "bisect_blowup",
    "convergence_order",
    "max_stable_dt",
    "measure_blowup_dt",
    "stability_limit",
    "stiffest_mode",
]
