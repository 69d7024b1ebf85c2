"""Plot of a run's energy ledger: what is in the body, what left it, and the drift."""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes

from ..energy import EnergyLedger


def plot_energy(
    ledger: EnergyLedger, ax: Axes | None = None, *, time_unit: str = "s", energy_unit: str = "J"
) -> Axes:
    """Kinetic, elastic, potential and total energy (solid), energy taken out per mechanism
    (dashed, cumulative) and the integrator's drift (dotted) against time."""
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(7, 4))
    columns = ledger.as_arrays()
    t = columns["time"]
    for name in ("kinetic", "elastic", "potential", "total"):
        ax.plot(t, columns[name], label=name, lw=2.0 if name == "total" else 1.2)
    for name, values in ledger.dissipated.items():
        if np.any(values):
            ax.plot(t, values, "--", lw=1.0, label=f"taken out: {name}")
    ax.plot(t, columns["drift"], ":", color="k", label="drift (integrator error)")
    ax.set(xlabel=f"time ({time_unit})", ylabel=f"energy ({energy_unit})", title="Energy ledger")
    ax.legend(fontsize="small", loc="best")
    ax.grid(alpha=0.3)
    return ax
