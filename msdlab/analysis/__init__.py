"""Analysis on top of the engine: measured blow-up time steps and convergence orders.

Re-exported from `msdlab`.
"""

from .measure import Convergence, bisect_blowup, convergence_order, measure_blowup_dt

__all__ = ["Convergence", "bisect_blowup", "convergence_order", "measure_blowup_dt"]
