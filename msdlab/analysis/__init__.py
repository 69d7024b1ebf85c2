"""Analysis on top of the engine: measured blow-up time steps, convergence
orders, and the Dask cluster that sweeps and grading can run on.

The measurements are re-exported from `msdlab`.
"""

from .measure import Convergence, bisect_blowup, convergence_order, measure_blowup_dt

__all__ = ["Convergence", "bisect_blowup", "convergence_order", "measure_blowup_dt"]
