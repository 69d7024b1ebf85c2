"""What both CPU backends keep between calls: the state they step (the host's own arrays,
loaded and handed back uncopied) and a body's springs as an edge list."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..model.springs import EdgeSprings

if TYPE_CHECKING:
    from ..model.body import Body


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


class KeptEdges:
    """A backend's edge list of a body's springs: the body's own, or its lattice laid out
    once per edit (``body.version``) and kept until the next."""

    _edges: tuple[object, int, EdgeSprings] = (None, -1, EdgeSprings.empty())

    def edges(self, body: Body) -> EdgeSprings:
        """The springs of ``body`` as an edge list (a lattice's laid out once per edit)."""
        if self._edges[0] is not body.spring_set or self._edges[1] != body.version:
            self._edges = (body.spring_set, body.version, body.spring_set.edges())
        return self._edges[2]
