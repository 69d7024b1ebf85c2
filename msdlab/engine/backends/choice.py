"""The choice of backend: by name, by ``MSDLAB_KERNEL``, or the readable one under a debugger."""

from __future__ import annotations

import ctypes
import os
import sys
import warnings

from .contract import SpringKernel
from .numpy import NumpyKernel

KERNELS = ("numba", "numpy", "warp")
CHOICES = (*KERNELS, "auto")  # "auto": warp on a GPU, numba elsewhere


def default_kernel() -> str:
    """The spring kernel to use: ``MSDLAB_KERNEL`` if set, else "numba" (while a debugger
    traces the program, a step runs on "numpy" all the same: `stepping_backend`).

    "numba" is the compiled loop of `msdlab.engine.backends.numba`; "numpy" is the readable
    array version of `msdlab.engine.backends.numpy`. Both apply the same `msdlab.engine.equations`.
    """
    name = os.environ.get("MSDLAB_KERNEL", "").strip().lower()
    if name:
        return checked_kernel_name(name, "MSDLAB_KERNEL")
    return "numba"


def kernel_left_to_msdlab(name: str | None) -> bool:
    """Whether a simulation asked for no kernel (``kernel=None`` and no ``MSDLAB_KERNEL``):
    then each step runs on the numpy kernel while a debugger traces the program."""
    return name is None and not os.environ.get("MSDLAB_KERNEL", "").strip()


def stepping_backend(chosen: SpringKernel, readable: SpringKernel) -> SpringKernel:
    """The backend of the next step of a simulation that asked for no kernel: the readable
    one while a debugger traces the program (`sys.gettrace`), so that its breakpoints in
    `msdlab.engine.equations` and in an integrator's update stop; else the ``chosen`` one.
    The one place a debugger changes what runs."""
    return readable if sys.gettrace() is not None else chosen


def checked_kernel_name(name: str, what: str) -> str:
    """``name`` if it is a kernel's name, else a ValueError naming ``what`` and the choices."""
    if name not in CHOICES:
        raise ValueError(f"{what} must be one of {', '.join(CHOICES)}, got {name!r}")
    return name


def compiling_first() -> bool:
    """Whether a run on the default kernel starts by compiling the numba kernel's loops
    (a first run on a machine: `msdlab.engine.backends.numba.loops_cached` is False)."""
    if default_kernel() != "numba":
        return False
    try:
        from .numba import loops_cached
    except ImportError:  # `make_kernel` warns and runs on numpy
        return False
    return loops_cached() is False


def make_kernel(name: str | None = None) -> SpringKernel:
    """The kernel called ``name`` ("numba" or "numpy"; default `default_kernel()`).

    numba is a dependency of msdlab; if it cannot be imported (a broken
    install), this warns and returns the numpy kernel, which computes the same.
    """
    name = default_kernel() if name is None else checked_kernel_name(name, "kernel")
    if name == "auto":
        name = "warp" if gpu_present() else "numba"
    if name == "numpy":
        return NumpyKernel()
    if name == "warp":
        return warp_kernel()
    try:
        from .numba import NumbaKernel  # the one optional, compiled backend
    except ImportError as error:
        warnings.warn(
            f"the numba kernel is unavailable ({error}); using the numpy kernel, which "
            "computes the same more slowly. Reinstall msdlab (pip install -e .) to fix it.",
            RuntimeWarning,
            stacklevel=3,
        )
        return NumpyKernel()
    return NumbaKernel()


def gpu_present() -> bool:
    """Whether Warp is installed and sees a CUDA device (``kernel="auto"`` then picks it).
    Warp is imported only where NVIDIA's driver library loads: elsewhere its start-up would
    print that it found no driver, for a choice the user left to msdlab."""
    try:
        ctypes.CDLL("nvcuda.dll" if sys.platform == "win32" else "libcuda.so.1")
        import warp
    except (OSError, ImportError):
        return False
    return warp.get_cuda_device_count() > 0


def warp_kernel() -> SpringKernel:
    """The Warp backend (`msdlab.engine.backends.warp`) in the precision
    ``MSDLAB_WARP_PRECISION`` names ("float64", the default, or "float32"), or an
    ImportError saying how to install Warp."""
    precision = os.environ.get("MSDLAB_WARP_PRECISION", "").strip().lower() or "float64"
    if precision not in ("float64", "float32"):
        raise ValueError(f"MSDLAB_WARP_PRECISION must be float64 or float32, got {precision!r}")
    try:
        from .warp import WarpKernel
    except ImportError as error:
        raise ImportError(
            f'kernel="warp" needs NVIDIA Warp ({error}); install it with pip install "msdlab[warp]"'
        ) from None
    return WarpKernel(precision=precision)
