"""msdlab: mass-spring-damper simulation for teaching.

import msdlab as msd
body = msd.Body.grid((10, 10, 10), spacing=0.1, stiffness=5000.0, neighbours=(1, 2, 3))
sim = msd.Simulation(body, msd.Verlet(damping=0.01), dt=1e-3,
                     forces=[msd.Gravity((0, -9.81, 0)), msd.Ground(height=0.0)])
trajectory = sim.run(duration=1.0, record_every=10)

Its names are imported when first used (`__getattr__`), so ``import msdlab`` alone
is quick: ``msd.Body`` imports `msdlab.body`, ``msd.max_stable_dt`` `msdlab.analysis`.

Debugging: under a debugger, or with ``MSDLAB_KERNEL=numpy`` set, the step runs on the
readable numpy kernel, so a breakpoint in ``msdlab.equations`` (``spring_force``) or in an
integrator's equation (``Verlet.update``) stops there.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

# The public names, by the module that defines them (`msdlab.analysis` imports scipy).
_PUBLIC = {
    "analysis": (
        "Convergence", "Mode", "bisect_blowup", "convergence_order", "max_stable_dt",
        "measure_blowup_dt", "stability_limit", "stiffest_mode",
    ),
    "body": ("Body", "rotation_matrix"),
    "constraint": ("Constraint", "StepState"),
    "dynamics": ("Dynamics",),
    "energy": (
        "EnergyLedger", "angular_momentum", "elastic_energy", "gravitational_energy",
        "kinetic_energy", "momentum",
    ),
    "errors": ("SimulationDiverged",),
    "forces": ("Force", "Gravity", "ViscousDamping"),
    "integrators": (
        "RK4", "ExplicitEuler", "ImplicitEuler", "Integrator", "SymplecticEuler",
        "VelocityVerlet", "Verlet",
    ),
    "interaction": ("Drag", "Grab", "Ground", "Prescribed", "SphereContact", "Walls"),
    "particle": ("Particle",),
    "simulation": ("Simulation", "Trajectory"),
    "spring": ("Spring",),
}  # fmt: skip
_DEFINED_IN = {name: module for module, names in _PUBLIC.items() for name in names}

__all__ = sorted(_DEFINED_IN)


def __getattr__(name: str) -> Any:
    """``msdlab.Body`` and the other public names, and submodules (``msdlab.analysis``),
    imported on first use."""
    if name in _DEFINED_IN:
        value = getattr(importlib.import_module(f".{_DEFINED_IN[name]}", __name__), name)
    else:
        value = _submodule(name)
    globals()[name] = value
    return value


def _submodule(name: str) -> Any:
    """The submodule ``msdlab.<name>``, imported; AttributeError if there is none."""
    if not name.startswith("__"):
        try:
            return importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as missing:
            if missing.name != f"{__name__}.{name}":
                raise
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
