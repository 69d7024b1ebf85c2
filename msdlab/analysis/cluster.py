"""Running independent calls side by side: worker processes here, or a Dask scheduler's workers.

``--cluster local:N`` runs them in a `concurrent.futures.ProcessPoolExecutor` of N processes;
any other value is a Dask scheduler's address (``tcp://host:8786``), whose
`Client.get_executor` has the same interface (Dask is the optional extra ``msdlab[cluster]``).
`run_all` runs a list of calls on either with a progress bar (tqdm) and gives each call's
result or, after its retries, its error, in the order of the calls:

- a call that raises runs again, up to ``retries`` times;
- a local process that dies (killed, out of memory) breaks its pool, and every call the
  pool was running fails with it: those calls run again one at a time in a new pool, so
  the call that kills its worker is known, and only it counts an attempt;
- on Dask the scheduler does both (``retries`` for errors, and a worker that dies makes it
  run the call on another one; a call that keeps killing workers ends in ``KilledWorker``).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import sys
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from tqdm.auto import tqdm

INSTALL = "pip install 'msdlab[cluster]'"

Call = tuple[tuple[Any, ...], dict[str, Any]]  # positional and keyword arguments
Done = Callable[[int, Any], None]  # called with a call's index and its result or error
# Workers start from a clean server process, not a fork of this one and its threads.
_START = multiprocessing.get_context("forkserver")


def parse_cluster(spec: str) -> tuple[str | None, int]:
    """``local:N`` → (None, N); anything else → (the scheduler address, 0)."""
    spec = spec.strip()
    if spec.startswith("local:"):
        count = spec.removeprefix("local:")
        if not count.isdigit() or int(count) < 1:
            raise ValueError(f"--cluster local:N needs N >= 1 worker processes, got {spec!r}")
        return None, int(count)
    if not spec or spec.startswith("local"):
        raise ValueError(f"--cluster takes a scheduler address or local:N, got {spec!r}")
    return spec, 0


@contextlib.contextmanager
def dask_executor(address: str, retries: int) -> Iterator[Executor]:
    """A `concurrent.futures.Executor` on the workers of the Dask scheduler at ``address``."""
    try:
        from dask.distributed import Client
    except ImportError:
        raise RuntimeError(f"--cluster needs Dask distributed: {INSTALL}") from None
    with Client(address) as client:
        yield client.get_executor(pure=False, retries=retries)


@contextlib.contextmanager
def tally(count: int, label: str, done: Done | None = None) -> Iterator[tuple[dict, Done]]:
    """The outcomes of ``count`` calls by index, and the function that records one, drawing
    a progress bar (tqdm) and calling ``done`` with each."""
    results: dict[int, Any] = {}
    with tqdm(total=count, desc=label, file=sys.stderr) as bar:

        def finished(index: int, outcome: Any) -> None:
            results[index] = outcome
            bar.update()
            if done is not None:
                done(index, outcome)

        yield results, finished


def run_all(
    spec: str,
    function: Callable[..., Any],
    calls: Sequence[Call],
    *,
    label: str,
    retries: int = 2,
    done: Done | None = None,
) -> list[Any]:
    """``function(*args, **kwargs)`` for each call on the workers of ``spec`` (see the module
    docstring): each result, or the exception its last attempt raised."""
    address, workers = parse_cluster(spec)
    with tally(len(calls), label, done) as (results, finished):
        if address is not None:
            with dask_executor(address, retries) as pool:
                collect(pool, function, calls, range(len(calls)), finished, retries=0)
        else:
            run_locally(workers, function, calls, results, finished, retries)
    return [results[i] for i in range(len(calls))]


def run_locally(
    workers: int,
    function: Callable[..., Any],
    calls: Sequence[Call],
    results: dict[int, Any],
    finished: Done,
    retries: int,
) -> None:
    """Run the calls not in ``results`` on ``workers`` local processes (see the module
    docstring): a pool that breaks is replaced, and the calls it was running (suspects)
    then run one at a time, before the others go on side by side."""
    attempts: Counter[int] = Counter()
    suspects: set[int] = set()
    while len(results) < len(calls):
        left = [i for i in range(len(calls)) if i not in results]
        alone = [i for i in left if i in suspects]
        in_flight = 1 if alone else workers
        with ProcessPoolExecutor(workers, mp_context=_START) as pool:
            ran, error = collect(
                pool, function, calls, alone or left, finished, retries, attempts, in_flight
            )
        if len(ran) > 1:  # which of them broke the pool is not known
            suspects.update(ran)
        elif ran:  # it ran alone: its worker died running it
            (culprit,) = ran
            attempts[culprit] += 1
            if attempts[culprit] > retries:
                finished(culprit, error)


def collect(
    pool: Executor,
    function: Callable[..., Any],
    calls: Sequence[Call],
    indices: Sequence[int],
    finished: Done,
    retries: int,
    attempts: Counter[int] | None = None,
    in_flight: int | None = None,
) -> tuple[list[int], BrokenProcessPool | None]:
    """Run the calls at ``indices`` on ``pool``, at most ``in_flight`` at a time, calling
    ``finished`` with each outcome (a call that raises runs again, up to ``retries``
    times). If the pool breaks, return at once the calls it was running and its error."""
    attempts = Counter() if attempts is None else attempts
    waiting = list(reversed(indices))
    running: dict[Future, int] = {}
    while waiting or running:
        while waiting and len(running) < (in_flight or len(calls)):
            index = waiting.pop()
            args, kwargs = calls[index]
            running[pool.submit(function, *args, **kwargs)] = index
        ended, _ = wait(running, return_when=FIRST_COMPLETED)
        for future in ended:
            index = running.pop(future)
            error = future.exception()
            if isinstance(error, BrokenProcessPool):
                return [index, *running.values()], error
            if error is not None:
                attempts[index] += 1
            if error is not None and attempts[index] <= retries:
                waiting.append(index)
            else:
                finished(index, future.result() if error is None else error)
    return [], None
