"""How a `Particle` or `Spring` object is bound to a row of a body's arrays.

Made on its own, such an object keeps its values in a dictionary. Added to a
body (``body.add_particle``), it is bound to the row the body gave it and from
then on reads and writes the body's arrays; ``body.particles[i]`` makes an
object bound to row i directly. The body only calls `bind` and `row`.
"""

from __future__ import annotations

from typing import Any, Protocol, TypeVar

import numpy as np

Self = TypeVar("Self", bound="Bound")


class BodyArrays(Protocol):
    """The arrays of a body that particles and springs read and write (see `Body`)."""

    positions: np.ndarray
    velocities: np.ndarray
    masses: np.ndarray
    fixed: np.ndarray
    spring_a: np.ndarray
    spring_b: np.ndarray
    stiffness: np.ndarray
    rest_lengths: np.ndarray
    spring_damping: np.ndarray


class Bound:
    """Base of objects that hold their own values until bound to row ``index`` of a body."""

    def __init__(self, **own: Any) -> None:
        self._body: BodyArrays | None = None
        self._index = -1
        self._own = own

    @classmethod
    def row(cls: type[Self], body: BodyArrays, index: int) -> Self:
        """An object of this class reading and writing row ``index`` of ``body``."""
        item = cls.__new__(cls)
        Bound.__init__(item)
        item.bind(body, index)
        return item

    def bind(self, body: BodyArrays, index: int) -> None:
        """Read and write row ``index`` of ``body`` from now on (its own values are dropped)."""
        if self._body is not None:
            kind = type(self).__name__
            raise ValueError(
                f"this {kind.lower()} already belongs to a body; make a new {kind} for each body"
            )
        self._body, self._index, self._own = body, int(index), {}

    @property
    def own_values(self) -> dict[str, Any]:
        """The values given at creation, while not bound to a body."""
        return dict(self._own)

    @property
    def is_bound(self) -> bool:
        """True once the object reads and writes a body's arrays."""
        return self._body is not None

    @property
    def index(self) -> int:
        """Index in its body (-1 while not in a body)."""
        return self._index
