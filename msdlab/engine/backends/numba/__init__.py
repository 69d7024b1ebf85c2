"""The numba backend: the same `msdlab.engine.equations`, compiled into loops.

Two files of compiled loops, which call the equations (`equations`: `msdlab.engine.equations`'s
own functions, compiled) one spring or particle at a time:

- `kernel`: `NumbaKernel`, with the methods of `backends.numpy.NumpyKernel` in the same order,
  and its loops: the edge loop over an edge list's springs sorted by their ends (forces,
  energy, Jacobian blocks), the finiteness check, the damping work, the ground's clamp,
  and an integrator's update function (for example `integrators.Verlet.update`) compiled
  into one loop over the particles with a = F/m, which also adds the spring forces the
  spring loop left to it;
- `lattice`: the backend's second loop, chosen when the springs are a lattice
  (`msdlab.engine.model.lattice.LatticeSprings`, the springs of `Body.grid`): forces and energy by
  neighbour offset with no list of springs, and its layout.

The loops are compiled on first use and cached on disk (``cache=True``), so compiling
is paid once per machine and numba version. Set the number of threads with
``NUMBA_NUM_THREADS`` or `numba.set_num_threads`.
"""

from .kernel import NumbaKernel, finite


def loops_cached() -> bool | None:
    """Whether numba's disk cache holds this version's compiled loops: False on the first
    run on a machine (or after an upgrade, or with an empty ``NUMBA_CACHE_DIR``), None if
    numba's cache cannot be read (its layout is numba's own)."""
    try:
        return bool(finite._cache._cache_file._load_index())  # empty: missing or stale
    except (AttributeError, OSError):
        return None


__all__ = ["NumbaKernel", "loops_cached"]
