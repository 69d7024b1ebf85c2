"""The numba backend: the same `msdlab.equations`, compiled into loops.

`kernel.NumbaKernel` has the methods of `kernels.NumpyKernel`, in the same order, on
compiled loops that call the equations (`equations`: `msdlab.equations`'s own
functions, compiled) one spring or particle at a time:

- `edges`: the edge loop over an edge list's springs, sorted by their ends: forces,
  energy, Jacobian blocks;
- `gather`: the lattice loop (`lattice.LatticeSprings`, the springs of `Body.grid`),
  by neighbour offset with no list of springs, laid out by `stencil`: forces, energy;
- `advance`: an integrator's update function (for example `integrators.Verlet.update`)
  compiled into one loop over the particles with a = F/m, which also adds the spring
  forces the spring loop left to it;
- `reductions` and `contact`: the finiteness check, the damping work, the ground's clamp.

The loops are compiled on first use and cached on disk (``cache=True``), so compiling
is paid once per machine and numba version. Set the number of threads with
``NUMBA_NUM_THREADS`` or `numba.set_num_threads`.
"""

from .kernel import NumbaKernel
from .reductions import finite


def loops_cached() -> bool | None:
    """Whether numba's disk cache holds this version's compiled loops: False on the first
    run on a machine (or after an upgrade, or with an empty ``NUMBA_CACHE_DIR``), None if
    numba's cache cannot be read (its layout is numba's own)."""
    try:
        return bool(finite._cache._cache_file._load_index())  # empty: missing or stale
    except (AttributeError, OSError):
        return None


__all__ = ["NumbaKernel", "loops_cached"]
