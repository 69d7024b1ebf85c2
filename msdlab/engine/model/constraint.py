"""The constraint interface: rules applied after each integrator step.

A constraint edits the new positions and velocities in place and returns the
energy it removed (J; negative when it put energy in) for the energy ledger.
The constraints themselves (ground, drag, walls, driven particles, grabbing)
are in `msdlab.interaction`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .body import Body

if TYPE_CHECKING:
    from ..backends.contract import SpringKernel


@dataclass
class StepState:
    """The end of a step, as constraints see it (edit ``x`` and ``v`` in place)."""

    body: Body
    x_old: np.ndarray  # positions at the start of the step (m)
    v_old: np.ndarray  # velocities at the start of the step (m/s)
    x: np.ndarray  # new positions (m)
    v: np.ndarray  # new velocities (m/s)
    time: float  # time at the end of the step (s)
    dt: float  # step (s)
    energy_of: Callable[[np.ndarray], float]  # energy (J) involving these particles now
    kernel: SpringKernel  # the step's backend (its `ground_clamp`)


class Constraint(ABC):
    """A rule applied after each integrator step; see the module docstring."""

    ledger_name = "other"
    example = ""  # how to create one, for error messages: "msd.Ground()"

    def check(self, body: Body) -> None:
        """Raise ValueError if this constraint cannot act on ``body``."""

    def plane(self, body: Body) -> tuple[np.ndarray, float, float] | None:
        """(unit normal (d,), height in m, friction) if this constraint is a ground plane a
        device backend clamps to in its own step (`Simulation`); None for any other."""
        return None

    @abstractmethod
    def apply(self, state: StepState) -> float:
        """Edit ``state.x``/``state.v``; return the energy removed (J)."""
