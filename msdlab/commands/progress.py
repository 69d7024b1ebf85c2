"""A small progress bar on stderr for runs that take more than a moment."""

from __future__ import annotations

import sys
import threading
import time
from types import TracebackType
from typing import TextIO

# What a wait for the first step usually is (the loops are cached on disk after that), and
# how long a first step may take without it (loading the cached loops takes up to 1.5 s).
STARTING = "starting: a first run on a machine also compiles msdlab's loops (about 10 s)"
FIRST_STEP_WAIT = 2.0


class ProgressBar:
    """Call with the number of steps done; draws ``[#####.....] 50%`` once ``delay`` s have passed.

    Quick runs print nothing. `close` (or leaving a ``with`` block) ends the line
    if a bar was drawn. The time left is estimated from the pace since the first
    call, so a slow first step (loading or compiling kernels) does not inflate
    it; until the steps have moved on from there, no estimate is shown. With
    ``starting_after`` (for bars called after every step: `FIRST_STEP_WAIT`), if
    no call has come by then, the bar says it is starting and why that may take
    a while (a first step that compiles the loops: 5-20 s).
    """

    def __init__(
        self,
        total: int,
        label: str = "",
        stream: TextIO | None = None,
        delay: float = 0.5,
        starting_after: float | None = None,
    ) -> None:
        self.total = max(int(total), 1)
        self.label = label
        self.stream = stream or sys.stderr
        self.delay = delay
        self.started = time.perf_counter()
        self.last_drawn = -1.0
        self.shown = False
        self.first: tuple[float, int] | None = None  # (time, steps done) at the first call
        self.width = 0  # of the longest line drawn
        self.closed = False
        self._lock = threading.Lock()  # the timer's thread and the caller's draw in turn
        self._starting: threading.Timer | None = None
        if starting_after is not None:
            self._starting = threading.Timer(starting_after, self._no_step_yet)
            self._starting.daemon = True
            self._starting.start()

    def __enter__(self) -> ProgressBar:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()

    def _no_step_yet(self) -> None:
        """Called ``starting_after`` s after the start: if no step has been done, say so."""
        with self._lock:
            if self.first is None and not self.closed:
                self.shown = True
                self._draw(f"{self.label} [{'.' * 30}]   0%  {STARTING}")

    def __call__(self, done: int) -> None:
        with self._lock:
            self._update(done)

    def _update(self, done: int) -> None:
        now = time.perf_counter()
        if self.first is None:
            self.first = (now, done)
        if now - self.started < self.delay or (now - self.last_drawn < 0.1 and done < self.total):
            return
        self.last_drawn, self.shown = now, True
        fraction = min(done / self.total, 1.0)
        filled = int(30 * fraction)
        elapsed = now - self.started
        since, done_then = self.first
        if done > done_then:
            pace = (now - since) / (done - done_then)  # s per step
            left = f"~{pace * (self.total - min(done, self.total)):4.1f} s left"
        else:
            left = "time left unknown yet"
        bar = "#" * filled + "." * (30 - filled)
        self._draw(f"{self.label} [{bar}] {100 * fraction:3.0f}%  {elapsed:5.1f} s, {left}")

    def _draw(self, line: str) -> None:
        self.stream.write(f"\r{line:<{self.width}}")  # blank out a longer line drawn before
        self.width = max(self.width, len(line))
        self.stream.flush()

    def close(self) -> None:
        """End the bar's line at 100% if it was drawn; later calls of the timer or of
        `close` write nothing."""
        if self._starting is not None:
            self._starting.cancel()  # if it is running already, the lock orders us
        with self._lock:
            if self.shown and not self.closed:
                self._update(self.total)
                self.stream.write("\n")
                self.stream.flush()
            self.closed = True
