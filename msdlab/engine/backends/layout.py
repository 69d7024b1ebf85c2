"""What a backend reads of a body, laid out once per edit of the body."""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ..model.body import Body
from ..model.lattice import LatticeSprings
from ..model.springs import EdgeSprings
from .jacobian import JacobianPattern


class Layout:
    """A body's springs, masses and fixed particles as the arrays every backend method is
    given: `Dynamics` lays a body out again only when it was edited (``body.version``),
    and no backend reads a `Body`. A backend that derives arrays of its own (sorted edges,
    a lattice's plan, copies on a device) derives them when it is given a new layout.

    ``springs`` is the body's spring set, an edge list (`EdgeSprings`) or a lattice
    (`LatticeSprings`); ``edges`` the same springs as an edge list (a lattice's laid out
    on first use); ``masses`` (N,) in kg and ``fixed`` (N,) are the body's own arrays,
    which edits write in place.
    """

    def __init__(self, body: Body) -> None:
        self.version = body.version
        self.springs: EdgeSprings | LatticeSprings = body.spring_set
        self.masses: np.ndarray = body.masses
        self.fixed: np.ndarray = body.fixed
        self.n_particles, self.dim = body.n_particles, body.dim or 3

    @cached_property
    def edges(self) -> EdgeSprings:
        """The springs as an edge list: the body's own, or its lattice laid out (once)."""
        return self.springs.edges()

    @cached_property
    def lattice(self) -> LatticeSprings | None:
        """The springs as a lattice (`Body.grid`'s), or None for an edge list."""
        return self.springs if isinstance(self.springs, LatticeSprings) else None

    @cached_property
    def pattern(self) -> JacobianPattern:
        """The sparsity of the springs' Jacobians (built on first use)."""
        return JacobianPattern(self.edges, self.n_particles, self.dim)
