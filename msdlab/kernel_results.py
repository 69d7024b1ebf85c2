"""What a backend returns, by name, and what it is given (`spring_kernel.SpringKernel`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp


class SpringSums(NamedTuple):
    """What a pass over the springs finds besides their forces."""

    stretch: float  # the largest |x_a - x_b| / l, to detect blow-ups (dimensionless)
    power: float  # Σ c ((v_a - v_b)·n)², the power the dashpots take out (W), >= 0


class Jacobians(NamedTuple):
    """The springs' ∂F/∂x (N/m) and ∂F/∂v (N·s/m), sparse (N·d × N·d)."""

    position: sp.csr_matrix
    velocity: sp.csr_matrix


class Advanced(NamedTuple):
    """One step of an integrator's update, and the `SpringSums` of the pass it took."""

    x: np.ndarray  # positions (N, d) in m
    v: np.ndarray  # velocities (N, d) in m/s
    stretch: float
    power: float


# An integrator's update ``update(x, v, a, dt, *coefficients) -> (x_new, v_new)``, a function
# of numbers or whole arrays (like `integrators.Verlet.update`).
Update = Callable[..., tuple[np.ndarray, np.ndarray]]
