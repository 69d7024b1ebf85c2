"""Errors raised by the engine, and the input checks shared by its classes."""

from __future__ import annotations

import math

import numpy as np


class SimulationDiverged(RuntimeError):
    """A simulation blew up: raised by `Simulation.step`/`run` in the step it happened.

    Attributes: ``step`` (index of the failing step), ``time`` (s, at the start of
    that step), ``diagnosis`` (what was seen and what to do about it) and
    ``trajectory`` (frames recorded before the failure, when raised by ``run``).
    The body keeps the last finite state, so it can be inspected or plotted.
    """

    def __init__(self, step: int, time: float, diagnosis: str) -> None:
        self.step = step
        self.time = time
        self.diagnosis = diagnosis
        self.trajectory = None
        super().__init__(f"simulation diverged in step {step} (t = {time:.6g} s): {diagnosis}")


def check_positive(name: str, value: float, hint: str = "") -> float:
    """Return ``value`` as a float if it is finite and > 0, else raise ValueError."""
    number = float(value)
    if not math.isfinite(number) or number <= 0:
        raise ValueError(f"{name} must be a positive finite number, got {value!r}. {hint}".strip())
    return number


def check_non_negative(name: str, values: np.ndarray | float, hint: str = "") -> None:
    """Raise ValueError unless every value is finite and >= 0."""
    array = np.asarray(values, dtype=float)
    bad = ~np.isfinite(array) | (array < 0)
    if np.any(bad):
        first = np.flatnonzero(bad.ravel())[0]
        where = f" at index {first}" if array.ndim else ""
        message = f"{name} must be finite and >= 0, got {array.ravel()[first]!r}{where}."
        raise ValueError(f"{message} {hint}".strip())


def check_finite_array(name: str, array: np.ndarray) -> None:
    """Raise ValueError naming the first row of ``array`` holding NaN or infinity."""
    if not np.all(np.isfinite(array)):
        row = np.flatnonzero(~np.all(np.isfinite(array.reshape(len(array), -1)), axis=1))[0]
        raise ValueError(
            f"{name} must be finite, but row {row} is {array[row].tolist()}; "
            "replace NaN/infinite values with real coordinates"
        )


def as_vectors(name: str, values: object, dim: int, count: int | None = None) -> np.ndarray:
    """Convert ``values`` to a float (count, dim) array, or say which shape was expected."""
    array = np.array(values, dtype=float)
    if count is not None and array.ndim == 1 and array.shape == (dim,):
        array = np.broadcast_to(array, (count, dim)).copy()
    expected = f"({count if count is not None else 'N'}, {dim})"
    if array.ndim != 2 or array.shape[1] != dim or (count is not None and len(array) != count):
        raise ValueError(f"{name} must have shape {expected}, got shape {array.shape}")
    check_finite_array(name, array)
    return array
