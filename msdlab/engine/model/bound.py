"""How a `Particle` or `Spring` object binds to a row of a body's arrays.

Made on its own, the object keeps its values in a dictionary. Added to a body
(``body.add_particle``) or read back as ``body.particles[i]``, it is bound to
that row and its `Field` attributes read and write the body's arrays.
"""

from __future__ import annotations

import operator
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Generic, TypeVar

Item = TypeVar("Item", bound="Bound")


class Field:
    """An attribute of a particle or spring: its own value, or row ``index`` of a body array.

    ``check`` validates and converts a value before it is stored; ``kind`` converts
    the value read (None: return the array row itself, a writeable view).
    """

    def __init__(
        self,
        array: str,
        doc: str,
        check: Callable[[Any], Any] | None = None,
        kind: type | None = float,
    ) -> None:
        self.array, self.__doc__, self.check, self.kind = array, doc, check, kind

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, item: Bound | None, owner: type | None = None) -> Any:
        if item is None:
            return self
        body = item.body
        value = item._own[self.name] if body is None else item.read(self.array)
        return value if self.kind is None or value is None else self.kind(value)

    def __set__(self, item: Bound, value: Any) -> None:
        if self.check is None:
            raise AttributeError(f"{self.name} cannot be changed; make a new {type(item).__name__}")
        value = self.check(value)
        if item.body is None:
            item._own[self.name] = value
        else:
            item.write(self.array, value)


class Bound:
    """Base of the objects whose `Field` attributes are bound to row ``index`` of ``body``."""

    def __init__(self) -> None:
        self.body: Any = None  # the `msdlab.Body` it is bound to
        self.index = -1  # row in the body; -1 while not in one
        self._own: dict[str, Any] = {}

    @classmethod
    def row(cls, body: Any, index: int) -> Any:
        """An object of this class reading and writing row ``index`` of ``body``."""
        item = cls.__new__(cls)
        Bound.__init__(item)
        item.bind(body, index)
        return item

    @classmethod
    def check_new(cls, item: object, method: str) -> None:
        """TypeError unless ``item`` is one of these, ValueError if it is in a body already
        (``method`` is the body's method that was given it)."""
        kind = cls.__name__
        if not isinstance(item, cls):
            raise TypeError(f"{method} takes a msdlab.{kind}, got {type(item).__name__}")
        if item.body is not None:
            raise ValueError(f"this {kind.lower()} already belongs to a body; make a new {kind}")

    def read(self, array: str) -> Any:
        """Row ``index`` of the body's ``array`` (a view for a row of several numbers)."""
        return getattr(self.body, array)[self.index]

    def write(self, array: str, value: Any) -> None:
        """Write ``value`` into row ``index`` of the body's ``array``."""
        getattr(self.body, array)[self.index] = value

    def bind(self, body: Any, index: int) -> None:
        """Read and write row ``index`` of ``body`` from now on (own values are dropped)."""
        if self.body is not None:
            kind = type(self).__name__
            raise ValueError(
                f"this {kind.lower()} already belongs to a body; make a new {kind} for each body"
            )
        self.body, self.index, self._own = body, int(index), {}


class Rows(Sequence, Generic[Item]):
    """``body.particles`` / ``body.springs``: objects bound to rows of the body's arrays."""

    def __init__(self, body: Any, kind: type[Item], count: int) -> None:
        self._body, self._kind, self._count = body, kind, count

    def __len__(self) -> int:
        return self._count

    def __getitem__(self, index: int) -> Item:  # type: ignore[override]
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(self._count))]  # type: ignore[return-value]
        position = operator.index(index)
        if not -self._count <= position < self._count:
            raise IndexError(
                f"{self._kind.__name__.lower()} {index} does not exist: the body has "
                f"{self._count} (indices 0 to {self._count - 1})"
            )
        return self._kind.row(self._body, position % self._count)

    def __iter__(self) -> Iterator[Item]:
        return (self[i] for i in range(self._count))
