"""A first run on a machine: the numpy kernel runs it while numba compiles in the background.

On a machine where numba's disk cache does not hold the numba kernel's loops yet
(`choice.compiling_first`), compiling them costs about 10 CPU seconds, more than
the whole of `msdlab demo` takes on the numpy kernel, which computes the same with
nothing to compile. So `start_engine` runs this process on the numpy kernel
(``MSDLAB_KERNEL=numpy``) and starts one background process, on one core at a low
priority, that compiles the loops a default run uses and leaves them in numba's cache
(`compile_engine`); the next run loads them. Measured by ``benchmarks/first_run.py``.

    python -m msdlab.commands.first_run   # compile the engine now, in the foreground
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

from ..engine.backends.choice import compiling_first

NOTE = (
    "first run on this machine: running on the numpy kernel while the compiled engine "
    "builds in the background (about 20 s, once); later runs use it"
)
# The runs whose loops the background process compiles (scene, settings): the demo's
# grid cube (the gathered springs) and a cloth (a body's springs as a list of edges).
WARM_UP = (("jelly-cube", {"size": 3}), ("cloth", {}))
WARM_UP_STEPS = 3
BACKGROUND = "--background"  # the argument of the background process: it holds the lock


def start_engine() -> bool:
    """On a first run, switch this process to the numpy kernel, start compiling the numba
    kernel in the background (unless another process is) and print `NOTE`; whether it did.
    Not on a system without POSIX file locks: there the run compiles as it goes."""
    if os.name != "posix" or not compiling_first():
        return False
    os.environ["MSDLAB_KERNEL"] = "numpy"
    with compiling_lock() as lock:
        if lock is not None:
            _compile_in_background(lock)
    print(NOTE, file=sys.stderr, flush=True)
    return True


def _compile_in_background(lock: int) -> None:
    """Start `compile_engine` in a process of its own on one core, handing it the ``lock``
    (held until it ends)."""
    environment = {key: value for key, value in os.environ.items() if key != "MSDLAB_KERNEL"}
    environment["NUMBA_NUM_THREADS"] = "1"  # one core; a one-thread run's loops
    subprocess.Popen(
        [sys.executable, "-m", __name__, BACKGROUND],
        env=environment,
        pass_fds=(lock,),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # it outlives this command, and a Ctrl-C here
    )


def compile_engine() -> None:
    """Run each `WARM_UP` scene a few steps on the numba kernel, so numba compiles its loops
    into the disk cache (nothing if the cache holds them)."""
    from ..scenes import get_scene

    if not compiling_first():
        return
    for name, settings in WARM_UP:
        get_scene(name).build(**settings).run(steps=WARM_UP_STEPS)


@contextlib.contextmanager
def compiling_lock(wait: bool = False, cache: str | None = None) -> Iterator[int | None]:
    """Hold the lock of compiling this msdlab into numba's cache ``cache`` (default
    ``NUMBA_CACHE_DIR``): yield its file descriptor, or None at once if another process
    holds it; with ``wait``, wait for that process to finish instead (POSIX only)."""
    import fcntl

    with open(lock_path(cache), "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX if wait else fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            yield None
            return
        yield lock.fileno()


def lock_path(cache: str | None = None) -> Path:
    """The lock file of compiling this msdlab into numba's cache ``cache`` (default
    ``NUMBA_CACHE_DIR``; one lock per pair)."""
    cache = os.environ.get("NUMBA_CACHE_DIR", "") if cache is None else cache
    key = f"{Path(__file__).resolve()}|{cache}"
    digest = hashlib.sha256(key.encode()).hexdigest()[:16]
    return Path(tempfile.gettempdir()) / f"msdlab-compiling-{digest}.lock"


if __name__ == "__main__":
    if sys.argv[1:] == [BACKGROUND]:  # started by `start_engine`, holding the lock
        with contextlib.suppress(OSError):
            os.nice(10)  # the command the student waits for goes first
        compile_engine()
    elif os.name != "posix":  # no file locks
        compile_engine()
    else:
        with compiling_lock(wait=True):
            compile_engine()
