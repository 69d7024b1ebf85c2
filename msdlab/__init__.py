"""msdlab: mass-spring-damper simulation for teaching.

import msdlab as msd
body = msd.Body.grid((10, 10, 10), spacing=0.1, stiffness=5000.0, neighbours=(1, 2, 3))
sim = msd.Simulation(body, msd.Verlet(damping=0.01), dt=1e-3,
                     forces=[msd.Gravity((0, -9.81, 0)), msd.Ground(height=0.0)])
trajectory = sim.run(duration=1.0, record_every=10)

The public names are imported below for every tool that reads code (an IDE's completions,
a type checker, a map of the imports), and at run time on first use (`__getattr__`), from
the same lines: ``import msdlab`` alone imports no engine, so that ``msdlab check``
starts at once; ``msd.Body`` imports `msdlab.engine.model.body`, ``msd.max_stable_dt``
`msdlab.analysis` (which imports scipy).

Debugging: under a debugger, or with ``MSDLAB_KERNEL=numpy`` set, the step runs on the
readable numpy kernel, so a breakpoint in ``msdlab.engine.equations`` (``spring_force``) or in an
integrator's equation (``Verlet.update``) stops there.
"""

from __future__ import annotations

import functools
import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

if TYPE_CHECKING:  # the public names; imported on first use at run time (`__getattr__`)
    from .analysis import (
        Convergence,
        Mode,
        bisect_blowup,
        convergence_order,
        max_stable_dt,
        measure_blowup_dt,
        stability_limit,
        stiffest_mode,
    )
    from .engine.dynamics import Dynamics
    from .engine.integrators import (
        RK4,
        ExplicitEuler,
        ImplicitEuler,
        Integrator,
        SymplecticEuler,
        VelocityVerlet,
        Verlet,
    )
    from .engine.model.body import Body
    from .engine.model.constraint import Constraint, StepState
    from .engine.model.errors import SimulationDiverged
    from .engine.model.forces import Force, Gravity, ViscousDamping
    from .engine.model.particle import Particle
    from .engine.model.rotation import rotation_matrix
    from .engine.model.spring import Spring
    from .engine.simulation.energy import (
        EnergyLedger,
        angular_momentum,
        elastic_energy,
        gravitational_energy,
        kinetic_energy,
        momentum,
    )
    from .engine.simulation.simulation import Simulation, Trajectory
    from .interaction import Drag, Grab, Ground, Prescribed, SphereContact, Walls


@functools.cache
def _defined_in() -> dict[str, str]:
    """Each public name and the module that defines it, read from the imports above (at
    the first name used, not at ``import msdlab``)."""
    import ast

    with open(__file__, encoding="utf-8") as source:
        tree = ast.parse(source.read())
    block = next(node for node in tree.body if isinstance(node, ast.If))
    return {alias.name: node.module for node in block.body for alias in node.names}


def __getattr__(name: str) -> Any:
    """The public names (``msdlab.Body``), their list (``__all__``) and the submodules
    (``msdlab.analysis``), imported on first use."""
    if name == "__all__":
        value: Any = sorted(_defined_in())
    elif name in _defined_in():
        value = getattr(importlib.import_module(f".{_defined_in()[name]}", __name__), name)
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
    return sorted({*globals(), *_defined_in()})
