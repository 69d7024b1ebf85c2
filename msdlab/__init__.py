"""msdlab: mass-spring-damper simulation for teaching.

import msdlab as msd
body = msd.Body.grid((10, 10, 10), spacing=0.1, stiffness=5000.0, neighbours=(1, 2, 3))
sim = msd.Simulation(body, msd.Verlet(damping=0.01), dt=1e-3,
                     forces=[msd.Gravity((0, -9.81, 0)), msd.Ground(height=0.0)])
trajectory = sim.run(duration=1.0, record_every=10)

Debugging: under a debugger, or with ``MSDLAB_KERNEL=numpy`` set, the step runs on the
readable numpy kernel, so a breakpoint in ``msdlab.equations`` (``spring_force``) or in an
integrator's equation (``Verlet.update``) stops there.
"""

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
from .body import Body, rotation_matrix
from .constraint import Constraint, StepState
from .dynamics import Dynamics
from .energy import (
    EnergyLedger,
    angular_momentum,
    elastic_energy,
    gravitational_energy,
    kinetic_energy,
    momentum,
)
from .errors import SimulationDiverged
from .forces import Force, Gravity, ViscousDamping
from .integrators import (
    RK4,
    ExplicitEuler,
    ImplicitEuler,
    Integrator,
    SymplecticEuler,
    VelocityVerlet,
    Verlet,
)
from .interaction import Drag, Grab, Ground, Prescribed, SphereContact, Walls
from .particle import Particle
from .simulation import Simulation, Trajectory
from .spring import Spring

__version__ = "0.1.0"

# fmt: off
__all__ = [
    "RK4", "Body", "Constraint", "Convergence", "Drag", "Dynamics", "EnergyLedger",
    "ExplicitEuler", "Force", "Grab", "Gravity", "Ground", "ImplicitEuler", "Integrator", "Mode",
    "Particle", "Prescribed", "Simulation", "SimulationDiverged", "SphereContact", "Spring",
    "StepState", "SymplecticEuler", "Trajectory", "VelocityVerlet", "Verlet", "ViscousDamping",
    "Walls", "angular_momentum", "bisect_blowup", "convergence_order", "elastic_energy",
    "gravitational_energy", "kinetic_energy", "max_stable_dt", "measure_blowup_dt", "momentum",
    "rotation_matrix", "stability_limit", "stiffest_mode",
]
# fmt: on
