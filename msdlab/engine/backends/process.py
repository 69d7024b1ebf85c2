"""Process-wide settings for a process that steps bodies: made by msdlab's own processes
(the command line, a course notebook's ``Course()``), never by importing msdlab (a library
must not change the process it is imported into)."""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import platform

# glibc's malloc: arrays below this many bytes come from the heap, ...
MMAP_THRESHOLD = 32 * 2**20
# ... which keeps up to this many freed bytes at its top instead of returning them.
TRIM_THRESHOLD = 64 * 2**20
_MALLOPT = {
    "MALLOC_MMAP_THRESHOLD_": (-3, MMAP_THRESHOLD),
    "MALLOC_TRIM_THRESHOLD_": (-1, TRIM_THRESHOLD),
}


def configure_process() -> None:
    """Settings for a process that steps bodies; a value the user set is kept.

    - Waiting threads sleep instead of spinning (``OMP_WAIT_POLICY=PASSIVE``): a
      spinning thread keeps waiting work off a shared core (a 0.5 ms step took 30 ms).
    - glibc keeps freed memory for the next step (`keep_freed_memory`).
    """
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    keep_freed_memory()


def keep_freed_memory() -> None:
    """Let glibc's malloc keep up to `TRIM_THRESHOLD` of freed heap and serve arrays below
    `MMAP_THRESHOLD` from it, here and in child processes (``MALLOC_*_`` variables).

    An integrator written with numpy arrays makes and frees the same temporaries
    every step; by default glibc gives that memory back to the system at the end
    of a step and faults it in again in the next (a 30³ velocity Verlet: 760 page
    faults and 5.1 ms a step instead of 3.8). Elsewhere than glibc, or when the
    user set either variable, nothing changes.
    """
    if platform.libc_ver()[0] != "glibc" or any(name in os.environ for name in _MALLOPT):
        return
    libc = ctypes.CDLL(ctypes.util.find_library("c"))
    for name, (parameter, value) in _MALLOPT.items():
        if libc.mallopt(parameter, value) == 1:
            os.environ[name] = str(value)
