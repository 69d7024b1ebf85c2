"""Progress bars (tqdm) for runs that take more than a moment, with msdlab's first-run note."""

from __future__ import annotations

import contextlib
import sys
import threading
from collections.abc import Callable, Iterator
from typing import TextIO

from tqdm.auto import tqdm

from ..engine.backends.choice import compiling_first

# The line before a first run on a machine compiles the engine (a cold `msdlab demo` less
# a warm one, benchmarks/first_run.py, on a quiet machine; cached on disk after that).
COMPILING = "compiling the engine once, about 10 s (later runs load it from the cache)"
# What a wait for the first step usually is otherwise (the cached loops are loaded, and a
# user's integrator's update loop is compiled once per process), and how long a first step
# may take without it (loading the cached loops takes up to 1.5 s).
STARTING = "starting: loading the engine (a few seconds)"
FIRST_STEP_WAIT = 2.0


@contextlib.contextmanager
def step_bar(
    total: int,
    label: str,
    *,
    file: TextIO | None = None,
    unit: str = "step",
    delay: float = 0.5,
    note_after: float = FIRST_STEP_WAIT,
    compiling: bool | None = None,
) -> Iterator[Callable[[int], None]]:
    """A bar drawn once ``delay`` s have passed, updated by calling it with the ``unit``s done.

    A run that starts by compiling the engine (``compiling``; by default
    `choice.compiling_first`) says so first (`COMPILING`); otherwise, if no step
    is done ``note_after`` s after the start, a line says why (`STARTING`).
    """
    compiling = compiling_first() if compiling is None else compiling
    if compiling:
        print(COMPILING, file=file or sys.stderr, flush=True)
    with tqdm(total=total, desc=label, unit=unit, delay=delay, file=file) as bar:
        note = threading.Timer(note_after, _note_no_step_yet, (bar,))
        note.daemon = True
        if not compiling:  # it has said why already
            note.start()
        try:
            yield lambda done: bar.update(done - bar.n)
        finally:
            note.cancel()


def _note_no_step_yet(bar: tqdm) -> None:
    if bar.n == 0 and not bar.disable:  # a closed bar is disabled
        bar.write(STARTING, file=bar.fp)


def count_bar(total: int, label: str, *, file: TextIO | None = None) -> tqdm:
    """A bar drawn at once, for a few long items (experiments, sweep runs, submissions)."""
    return tqdm(total=total, desc=label, file=file)
