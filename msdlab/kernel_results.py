"""What a spring kernel returns, by name (`spring_kernel.SpringKernel`)."""

from __future__ import annotations

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
