"""A small progress bar on stderr for runs that take more than a moment."""

from __future__ import annotations

import sys
import time
from typing import TextIO


class ProgressBar:
    """Call with the number of steps done; draws ``[#####.....] 50%`` once ``delay`` s have passed.

    Quick runs print nothing. `close` ends the line if a bar was drawn.
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

    def __call__(self, done: int) -> None:
        now = time.perf_counter()
        if now - self.started < self.delay or (now - self.last_drawn < 0.1 and done < self.total):
            return
        self.last_drawn, self.shown = now, True
        fraction = min(done / self.total, 1.0)
        filled = int(30 * fraction)
        elapsed = now - self.started
        left = elapsed * (1 - fraction) / fraction if fraction > 0 else 0.0
        bar = "#" * filled + "." * (30 - filled)
        self.stream.write(
            f"\r{self.label} [{bar}] {100 * fraction:3.0f}%  {elapsed:5.1f} s, ~{left:4.1f} s left"
        )
        self.stream.flush()

    def close(self) -> None:
        if self.shown:
            self(self.total)
            self.stream.write("\n")
            self.stream.flush()
