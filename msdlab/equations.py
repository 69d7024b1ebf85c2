"""The equations of the engine, each written once.

Every function here is plain arithmetic, so it works on numbers and, by numpy
broadcasting, on whole arrays. The numpy kernel (`msdlab.kernels`) calls them
on arrays of all springs or particles; the numba kernel (`msdlab.compiled`)
compiles the same functions and calls them on one spring or one coordinate
at a time. `Spring`, the kernels and the integrators all use these, so there
is no second copy of a formula to keep in step.

Equation numbers are those of the course brief.
"""

from __future__ import annotations

import numpy as np


def spring_force(
    stiffness: float, rest: float, length: float, damping: float, rate: float
) -> float:
    """Force (N) along a spring on its end ``a``, eq. (1.2) plus the dashpot.

    ``rate`` ṡ = (v_a - v_b)·n (m/s) is how fast the spring lengthens (0 without
    a dashpot). Positive pushes ``a`` away from ``b``::

        f = k (l - |x_a - x_b|) - c ṡ,   n = (x_a - x_b) / |x_a - x_b|

    The force vector on ``a`` is f·n and ``b`` feels -f·n (eq. 1.1 sums them).
    """
    return stiffness * (rest - length) - damping * rate


def spring_energy(stiffness: float, rest: float, length: float) -> float:
    """Elastic energy ½ k (|x_a - x_b| - l)² (J) of a spring of the given length."""
    return 0.5 * stiffness * (length - rest) ** 2


def dashpot_power(damping: float, rate: float) -> float:
    """Power c ṡ² (W) a dashpot takes out when its spring lengthens at ``rate`` ṡ (m/s)."""
    return damping * rate**2


def transverse_stiffness(stiffness: float, rest: float, length: float) -> float:
    """Stiffness k·max(0, 1 - l/|d|) (N/m) of a spring across its direction n.

    With it the spring's Jacobian block is B = k n nᵀ + k_t (I - n nᵀ); it is 0
    for a compressed spring (as Baraff & Witkin do, so that -∂F/∂x stays
    positive semi-definite).
    """
    return stiffness * np.maximum(0.0, 1.0 - rest / length)


def inverse_mass(mass: float, free: bool) -> float:
    """1/m (1/kg) for a free particle, 0 for a fixed one (so it never accelerates)."""
    return free / mass


def acceleration(force: float, inverse_mass: float) -> float:
    """Newton's second law a = F/m (m/s²), written with the inverse mass."""
    return force * inverse_mass


def kinetic_energy(masses: np.ndarray, velocities: np.ndarray) -> float:
    """½ Σ m |v|² (J) of particles of ``masses`` (N,) moving at ``velocities`` (N, d)."""
    return float(0.5 * np.sum(masses * np.einsum("ij,ij->i", velocities, velocities)))
