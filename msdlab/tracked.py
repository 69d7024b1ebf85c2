"""A numpy array that tells its owner when it is written in place.

`Body` hands out its spring values (``body.stiffness``, ``rest_lengths``,
``spring_damping``) as `TrackedArray` views, so that an edit such as
``body.stiffness[3] = 50.0`` or ``body.spring_damping *= 2`` marks the body's
spring values changed (`Body.parameters_version`) at once: kernels that keep
something derived from the values (a table of distinct springs, a grid
stencil) know to rebuild it. Reading never counts as a change.

Views and slices of a tracked array are tracked too; results of arithmetic
(``body.stiffness * 2``) are plain arrays. Writes that bypass numpy's array
interface (``array.view(np.ndarray)[0] = ...``, or the raw memory) are not seen.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

# numpy functions that write into an array argument.
_WRITERS = {np.copyto, np.put, np.place, np.putmask, np.fill_diagonal}
_IN_PLACE = (
    "__iadd__",
    "__isub__",
    "__imul__",
    "__itruediv__",
    "__ifloordiv__",
    "__imod__",
    "__ipow__",
    "__imatmul__",
    "__iand__",
    "__ior__",
    "__ixor__",
    "__ilshift__",
    "__irshift__",
    "fill",
    "put",
    "itemset",
    "sort",
    "partition",
    "resize",
    "setfield",
    "byteswap",
)


class TrackedArray(np.ndarray):
    """An ndarray view whose in-place writes call ``on_write()`` (see the module docstring)."""

    on_write: Callable[[], None] | None

    @classmethod
    def of(cls, array: np.ndarray, on_write: Callable[[], None]) -> TrackedArray:
        """A tracked view of ``array``; writing through it calls ``on_write()``."""
        tracked = array.view(cls)
        tracked.on_write = on_write
        return tracked

    def __array_finalize__(self, parent: Any) -> None:
        """Views of a tracked array are tracked; copies (``copy``, ``flatten``) are not."""
        self.on_write = getattr(parent, "on_write", None) if self.base is not None else None

    def _written(self) -> None:
        if self.on_write is not None:
            self.on_write()

    def __setitem__(self, key: Any, value: Any) -> None:
        self._written()
        super().__setitem__(key, value)

    def __array_ufunc__(self, ufunc: np.ufunc, method: str, *inputs: Any, **kwargs: Any) -> Any:
        """Run the ufunc on plain arrays; mark the owner if a tracked array is written."""
        outputs = kwargs.get("out", ())
        for output in outputs:
            if isinstance(output, TrackedArray):
                output._written()
        plain = tuple(_plain(value) for value in inputs)
        if outputs:
            kwargs["out"] = tuple(_plain(output) for output in outputs)
        result = getattr(ufunc, method)(*plain, **kwargs)
        if outputs and len(outputs) == 1 and isinstance(outputs[0], np.ndarray):
            return outputs[0]
        return result

    def __array_function__(self, func: Any, types: Any, args: Any, kwargs: Any) -> Any:
        """Mark the owner when a writing numpy function (``np.copyto``, ...) gets this array."""
        if func in _WRITERS and args and isinstance(args[0], TrackedArray):
            args[0]._written()
        return super().__array_function__(func, types, args, kwargs)


def _plain(value: Any) -> Any:
    """``value`` as a plain ndarray view if it is tracked, else as it is."""
    return value.view(np.ndarray) if isinstance(value, TrackedArray) else value


def _in_place(name: str) -> Callable[..., Any]:
    """The ndarray method ``name``, calling ``on_write()`` first."""
    method = getattr(np.ndarray, name)

    def written(self: TrackedArray, *args: Any, **kwargs: Any) -> Any:
        self._written()
        return method(self, *args, **kwargs)

    written.__name__ = name
    return written


for _name in _IN_PLACE:
    if hasattr(np.ndarray, _name):
        setattr(TrackedArray, _name, _in_place(_name))
