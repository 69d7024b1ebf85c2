"""Plot of a run's energy ledger: what is in the body, what left it, and the drift."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .. import EnergyLedger
from .view import save_figure


def plot_energy(
    ledger: EnergyLedger,
    ax: Axes | None = None,
    *,
    time_unit: str = "s",
    energy_unit: str = "J",
    save: str | Path | None = None,
) -> Figure:
    """Kinetic, elastic, potential and total energy (solid), energy taken out per mechanism
    (dashed, cumulative) and the integrator's drift (dotted) against time; return the
    figure, also written to ``save`` (.png, .pdf, .svg) if given."""
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(8, 4.5), layout="constrained")
    columns = ledger.as_arrays()
    t = columns["time"]
    for name in ("kinetic", "elastic", "potential", "total"):
        ax.plot(t, columns[name], label=name, lw=2.0 if name == "total" else 1.2)
    for name, values in ledger.dissipated.items():
        if np.any(values):
            ax.plot(t, values, "--", lw=1.0, label=f"taken out: {name}")
    ax.plot(t, columns["drift"], ":", color="k", label="drift (integrator error)")
    ax.set(xlabel=f"time ({time_unit})", ylabel=f"energy ({energy_unit})", title="Energy ledger")
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.grid(alpha=0.3)
    return save_figure(ax.figure, save)
