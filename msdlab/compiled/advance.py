"""The update loop: an integrator's update function compiled into one loop over the particles.

`compile_advance` turns an update such as `integrators.Verlet.update` into a
loop that computes a = F/m (plus gravity's g) and the update together, and adds
the spring forces the spring loops left pending in the same pass. numba caches a
compiled loop on disk only for a function defined in a file, so for msdlab's own
updates (the integrators') the loop is written once into a file of its own in a
cache folder (`loop_file`), and later processes load it compiled instead of
compiling it again (about 0.5 s); a user's update is compiled once per process.
"""

from __future__ import annotations

import hashlib
import importlib.util
import inspect
import os
import sys
from collections.abc import Callable
from pathlib import Path

import numba

from .. import equations as physics
from . import equations
from .equations import acceleration

LOOP = """\
import numba

from msdlab.compiled.advance import particle_acceleration
{import_update}

scalar = numba.njit({update})


@numba.njit(parallel={threads}, cache={cache})
def advance(x, v, forces, partial, field, masses, fixed, dt, coefficients, x_new, v_new):
    for i in numba.prange(len(masses)):
        for q in range(x.shape[1]):
            a = particle_acceleration(i, q, forces, partial, field, masses, fixed)
            x_new[i, q], v_new[i, q] = scalar(x[i, q], v[i, q], a, dt, *coefficients)
"""


@numba.njit(cache=True, inline="always")
def particle_acceleration(i, q, forces, partial, field, masses, fixed):
    """a = (F + m·g)/m (m/s²) of particle i along q, 0 if fixed. F is ``forces`` (N, d)
    plus the threads' ``partial`` forces (T, N, d; T = 0 if none), added in the order
    the edge loop adds them (see `edges.spring_forces_parallel`)."""
    total = forces[i, q]
    for t in range(len(partial)):
        total += partial[t, i, q]
    return acceleration(total + masses[i] * field[q], masses[i], not fixed[i])


def compile_advance(update: Callable, threads: bool) -> Callable:
    """A loop over the particles doing a = (F + m·g)/m then ``update`` per coordinate.

    F is ``forces`` (N, d) plus the threads' ``partial`` forces (`particle_acceleration`);
    ``forces`` may be a view, such as the grid gather's forces by coordinate
    transposed (numba compiles the loop once for each layout it is given). The new
    state goes to ``x_new`` and ``v_new``. With ``threads`` the particles are split
    between the threads (each writes only its own rows). numba compiles it at its
    first call (or loads it from its disk cache, see `loop_file`), which raises a
    numba error if it cannot.
    """
    path = loop_file(update, threads)
    if path is not None:
        spec = importlib.util.spec_from_file_location(f"msdlab_loop_{path.stem}", path)
        module = sys.modules[spec.name] = importlib.util.module_from_spec(spec)  # numba's cache
        try:  # finds its loop's globals by the module's name
            spec.loader.exec_module(module)
            return module.advance
        except (OSError, RuntimeError):  # numba found no folder to write its cache in
            del sys.modules[spec.name]
    namespace = {"update": update}
    exec(LOOP.format(import_update="", update="update", threads=threads, cache=False), namespace)
    return namespace["advance"]


def loop_file(update: Callable, threads: bool) -> Path | None:
    """The file of `LOOP` for ``update``, written once into the cache folder (numba's
    ``NUMBA_CACHE_DIR``, else the user's cache), named by a hash of everything the
    compiled loop depends on: the loop, the module of ``update`` and the equations.
    None for an update that is not msdlab's own (a user's module may change where
    the hash does not see it), or if the folder cannot be written."""
    module, name = getattr(update, "__module__", "") or "", getattr(update, "__qualname__", "")
    if not module.startswith("msdlab.") or not _imports_as(update, module, name):
        return None
    head = name.split(".")[0]
    source = LOOP.format(
        import_update=f"from {module} import {head}", update=name, threads=threads, cache=True
    )
    files = (inspect.getsourcefile(update), __file__, equations.__file__, physics.__file__)
    key = [source, numba.__version__, *(Path(file).read_text(encoding="utf-8") for file in files)]
    digest = hashlib.sha256("\0".join(key).encode()).hexdigest()[:16]
    folder = Path(numba.config.CACHE_DIR or _user_cache()) / "msdlab_loops"
    path = folder / f"advance_{digest}.py"
    try:
        if not path.is_file():
            folder.mkdir(parents=True, exist_ok=True)
            partial = path.with_suffix(f".{os.getpid()}.tmp")
            partial.write_text(source, encoding="utf-8")
            os.replace(partial, path)  # whole, even with another process writing it too
    except OSError:
        return None
    return path


def _imports_as(update: Callable, module: str, name: str) -> bool:
    """Whether ``from module import ...`` then ``name`` gives ``update`` itself."""
    try:
        found: object = importlib.import_module(module)
        for part in name.split("."):
            found = getattr(found, part)
    except (ImportError, AttributeError):
        return False
    return found is update


def _user_cache() -> Path:
    """The user's cache folder for msdlab (``XDG_CACHE_HOME`` or ~/.cache)."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "msdlab"
