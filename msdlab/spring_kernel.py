"""The spring kernel interface: what `Dynamics` needs from a backend, and choosing one.

A spring kernel computes, for all springs of a body at once, what `Spring.force`
computes for one (eq. 1.1-1.2 with the dashpot), their energy, dashpot power
and Jacobians, and runs an integrator's update with a = F/m. `Dynamics` calls
only the methods of `SpringKernel`; it never knows which backend runs:
`kernels.NumpyKernel` (readable, whole arrays) or `msdlab.compiled.NumbaKernel`
(compiled loops, the default). Both apply the same `msdlab.equations`.
"""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Callable
from typing import Protocol

import numpy as np
import scipy.sparse as sp

from .body import Body
from .jacobian import JacobianPattern
from .kernels import NumpyKernel

KERNELS = ("numba", "numpy")
Update = Callable[..., tuple[np.ndarray, np.ndarray]]


class SpringKernel(Protocol):
    """What `Dynamics` needs from a spring kernel; `NumpyKernel` and `NumbaKernel` have it."""

    name: str

    def add_spring_forces(
        self, body: Body, x: np.ndarray, v: np.ndarray, out: np.ndarray, springs: np.ndarray | None
    ) -> tuple[float, float]:
        """Add the spring and dashpot forces (N) to ``out``; return (largest stretch, power W)."""

    def elastic_energy(self, body: Body, x: np.ndarray, springs: np.ndarray | None) -> float:
        """Energy (J) stored in the springs (or in the given ones)."""

    def dashpot_power(self, body: Body, x: np.ndarray, v: np.ndarray) -> float:
        """Power (W) the dashpots take out at (x, v)."""

    def finite(self, x: np.ndarray, v: np.ndarray) -> bool:
        """Whether every position and velocity (N, d) is a finite number."""

    def damping_work(
        self, masses: np.ndarray, v_before: np.ndarray, v_after: np.ndarray, factor: float
    ) -> float:
        """`equations.damping_work`: the energy (J) a velocity factor per step takes out."""

    def jacobians(
        self, body: Body, x: np.ndarray, pattern: JacobianPattern
    ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """∂F/∂x and ∂F/∂v of the springs on ``pattern`` (see `kernels.spring_jacobians`)."""

    def acceleration(
        self, body: Body, x: np.ndarray, v: np.ndarray, forces: np.ndarray, field: np.ndarray
    ) -> tuple[np.ndarray, float, float]:
        """a = (F + m·g)/m (N, d), F the spring forces, g = ``field`` (d,) in m/s², 0 for fixed;
        with the largest stretch and the dashpot power (W). ``forces`` (N, d) is scratch."""

    def to_acceleration(self, body: Body, forces: np.ndarray) -> np.ndarray:
        """Accelerations a = F/m (N, d) from forces (N, d), 0 for fixed (may reuse ``forces``)."""

    def advance(
        self,
        update: Update,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
    ) -> tuple[np.ndarray, np.ndarray]:
        """``update(x, v, a, dt, *coefficients)`` with a = (F + m·g)/m, g = ``field`` (d,)
        in m/s² (0 for fixed particles)."""

    def advance_with_springs(
        self,
        update: Update,
        body: Body,
        x: np.ndarray,
        v: np.ndarray,
        forces: np.ndarray,
        field: np.ndarray,
        dt: float,
        coefficients: tuple[float, ...],
    ) -> tuple[np.ndarray, np.ndarray, float, float]:
        """The spring forces, then `advance`: (x_new, v_new, largest stretch, dashpot power W).
        ``forces`` (N, d) is the kernel's scratch: its content is not read."""


def default_kernel() -> str:
    """The spring kernel to use: ``MSDLAB_KERNEL`` if set; else "numpy" while a debugger
    traces the program (`sys.gettrace`), so its breakpoints in `msdlab.equations` and in
    an integrator's update stop; else "numba".

    "numba" is the compiled loop of `msdlab.compiled`; "numpy" is the readable
    array version of `msdlab.kernels`. Both apply the same `msdlab.equations`.
    """
    name = os.environ.get("MSDLAB_KERNEL", "").strip().lower()
    if name:
        return checked_kernel_name(name, "MSDLAB_KERNEL")
    return "numpy" if sys.gettrace() is not None else "numba"


def checked_kernel_name(name: str, what: str) -> str:
    """``name`` if it is a kernel's name, else a ValueError naming ``what`` and the choices."""
    if name not in KERNELS:
        raise ValueError(f"{what} must be one of {', '.join(KERNELS)}, got {name!r}")
    return name


def compiling_first() -> bool:
    """Whether a run on the default kernel starts by compiling the numba kernel's loops
    (a first run on a machine: `msdlab.compiled.loops_cached` is False)."""
    if default_kernel() != "numba":
        return False
    try:
        from .compiled import loops_cached
    except ImportError:  # `make_kernel` warns and runs on numpy
        return False
    return loops_cached() is False


def make_kernel(name: str | None = None) -> SpringKernel:
    """The kernel called ``name`` ("numba" or "numpy"; default `default_kernel()`).

    numba is a dependency of msdlab; if it cannot be imported (a broken
    install), this warns and returns the numpy kernel, which computes the same.
    """
    name = default_kernel() if name is None else checked_kernel_name(name, "kernel")
    if name == "numpy":
        return NumpyKernel()
    try:
        from .compiled import NumbaKernel  # the one optional, compiled backend
    except ImportError as error:
        warnings.warn(
            f"the numba kernel is unavailable ({error}); using the numpy kernel, which "
            "computes the same more slowly. Reinstall msdlab (pip install -e .) to fix it.",
            RuntimeWarning,
            stacklevel=3,
        )
        return NumpyKernel()
    return NumbaKernel()
