"""A small progress bar on stderr for runs that take more than a moment."""

from __future__ import annotations

import sys
import time
from typing import TextIO


class ProgressBar:
    """Call with the number of steps done; draws ``[#####.....] 50%`` once ``delay`` s have passed.

    Quick runs print nothing. `close` ends the line if a bar was drawn. The time
    left is estimated from the pace since the first call, so a slow first step
    (loading or compiling kernels) does not inflate it; until the steps have
    moved on from there, no estimate is shown.
    """

    def __init__(
        self, total: int, label: str = "", stream: TextIO | None = None, delay: float = 0.5
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

    def __call__(self, done: int) -> None:
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
        line = f"{self.label} [{bar}] {100 * fraction:3.0f}%  {elapsed:5.1f} s, {left}"
        self.stream.write(f"\r{line:<{self.width}}")  # blank out a longer line drawn before
        self.width = max(self.width, len(line))
        self.stream.flush()

    def close(self) -> None:
        if self.shown:
            self(self.total)
            self.stream.write("\n")
            self.stream.flush()
