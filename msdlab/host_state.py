"""The state a backend on the CPU steps: the host's own arrays, loaded and handed back uncopied."""

from __future__ import annotations

import numpy as np


class HostState:
    """`SpringKernel.load` and `SpringKernel.state` of a backend whose arrays live in the
    host's memory (numpy, numba): it keeps the arrays it is given and hands the same ones
    back, so loading the body's state and asking for it copy nothing."""

    _state: tuple[np.ndarray, np.ndarray]

    def load(self, x: np.ndarray, v: np.ndarray) -> None:
        """Step from positions ``x`` (m) and velocities ``v`` (m/s), (N, d), kept as they are."""
        self._state = (x, v)

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """The positions (m) and velocities (m/s) being stepped: the arrays last loaded."""
        return self._state
