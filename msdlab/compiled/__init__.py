"""The numba backend: the same `msdlab.equations`, compiled into loops.

`kernels.NumpyKernel` applies the equations to (E, d) arrays of all springs,
then sums them per particle. `NumbaKernel` compiles the same functions
(`equations`, here) into loops, in one module per loop:

- `edges`: the edge loop over the springs, sorted by their ends, for any body;
- `gather`: grid bodies (`stencil`) whose springs share their values per
  offset go by offset instead, with no list of springs;
- `advance`: an integrator's update function (for example
  `integrators.Verlet.update`) compiled into one loop over the particles that
  computes a = F/m (plus gravity's g) and the update together; numba compiles the
  function itself, and keeps msdlab's integrators' loops in its disk cache (a user's
  update is compiled once per process). The spring forces not
  yet summed (the edge loop's threads' buffers, or the gather's forces by
  coordinate) are added in that loop too, not in a pass of their own;
- `contact`: the ground's clamp, one loop over the particles;
- `reductions`: the finiteness check of the state;
- `kernel`: `NumbaKernel`, which keeps what a body needs between calls and
  picks the loops.

The spring loops are compiled on first use and cached on disk (``cache=True``),
so compiling is paid once per machine and numba version. Set the number of
threads with ``NUMBA_NUM_THREADS`` or `numba.set_num_threads`.
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
