"""The hand's path as the page made it, played back to the engine one step at a time.

The page sends a held particle's target at each mouse move with the move's time (ms,
the page's clock), but the moves reach the kernel in bursts: two or three at once, then
none for a frame or two. Given to `Grab` as they come, a step would carry a burst's
moves and the next none: the held particle jerks, and the ledger's booking of the hand's
work (exact to second order in the move per step, `interaction.constraints.lead`) errs
by several per cent of the work. Played back at the pace the hand made them, each step
moves the particle by the hand's motion over that step's time, as a `Grab` moved along
a path in a script. The playback lags the newest move by the longest delay seen in the
drag; more than `LAG_LIMIT` behind, it plays `CATCH_UP` times faster until it is back
within it (a jump would put a long move into one step), and it never lags by more than
`JUMP_LIMIT` (an engine slower than real time).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence

import numpy as np

LAG_LIMIT = 250.0  # ms the playback may lag the newest move at the hand's pace
CATCH_UP = 2.0  # times the hand's pace, further behind than that
JUMP_LIMIT = 1000.0  # ms the playback lags at most: further behind, it jumps


class HandPath:
    """The targets (world units) a hand passed through, with their times (ms), and the
    playback's clock: the time whose target the held particle is given now."""

    def __init__(self, time: float, target: Sequence[float]) -> None:
        self.points: deque[tuple[float, np.ndarray]] = deque([(time, np.array(target, float))])
        self.clock = time

    def add(self, time: float, target: Sequence[float]) -> None:
        """The hand at ``target`` at ``time`` (ms); a move out of order replaces the newest.
        A move to where the hand is, once the playback has caught up, says the hand stood
        still until ``time``: the playback goes on from there (the keyboard sends one
        before each of its moves), not from the last move, up to `JUMP_LIMIT` behind."""
        point = (time, np.array(target, dtype=float))
        if time <= self.points[-1][0]:
            self.points[-1] = (self.points[-1][0], point[1])
        elif self.caught_up and np.array_equal(point[1], self.points[-1][1]):
            self.points[-1] = point
            self.clock = time
        else:
            self.points.append(point)

    @property
    def newest(self) -> float:
        """The time (ms) of the newest move."""
        return self.points[-1][0]

    @property
    def caught_up(self) -> bool:
        """Whether the playback has reached the newest move."""
        return self.clock >= self.newest

    def advance(self, ms: float) -> np.ndarray:
        """Move the clock on by ``ms`` (`CATCH_UP` times that if it lags by more than
        `LAG_LIMIT`; no further than the newest move) and return the target there, on the
        straight line between the two moves around it."""
        pace = CATCH_UP if self.newest - self.clock > LAG_LIMIT else 1.0
        self.clock = max(self.clock + pace * ms, self.newest - JUMP_LIMIT)
        self.clock = min(self.clock, self.newest)
        while len(self.points) > 1 and self.points[1][0] <= self.clock:
            self.points.popleft()
        (t0, x0), *later = self.points
        if not later:
            return x0.copy()
        t1, x1 = later[0]
        return x0 + (x1 - x0) * (self.clock - t0) / (t1 - t0)
