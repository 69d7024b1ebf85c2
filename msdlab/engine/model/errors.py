"""Errors raised by the engine, and the input checks its classes share."""

from __future__ import annotations

import math

import numpy as np


class SimulationDiverged(RuntimeError):
    """A simulation blew up: raised by `Simulation.step`/`run` in the step it happened.

    ``step`` (index of the failing step), ``time`` (s, at its start), ``diagnosis``
    (what was seen, what to do) and ``trajectory`` (frames before the failure, when
    raised by ``run``). The body keeps the last finite state.
    """

    def __init__(self, step: int, time: float, diagnosis: str) -> None:
        self.step, self.time, self.diagnosis = step, time, diagnosis
        self.trajectory = None
        super().__init__(f"simulation diverged in step {step} (t = {time:.6g} s): {diagnosis}")


def shown(value: object) -> str:
    """``value`` as an error message shows it: numbers and arrays plainly (``-5.0``,
    ``[0.0, -9.81]``), never as numpy reprs such as ``np.float64(-5.0)``."""
    if isinstance(value, (np.generic, np.ndarray)):
        value = value.tolist()
    return repr(value)


def as_numbers(name: str, values: object, hint: str = "") -> np.ndarray:
    """``values`` (a number or numbers) as a float array, else ValueError naming ``name``,
    what was given and ``hint`` (say what works: ``"e.g. stiffness=100.0"``)."""
    try:
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        message = f"{name} must be a number, got {shown(values)}."
        raise ValueError(f"{message} {hint}".strip()) from None


def check_positive(name: str, value: float, hint: str = "") -> float:
    """``value`` as a float if it is finite and > 0, else ValueError."""
    number = float(as_numbers(name, value, hint))
    if not math.isfinite(number) or number <= 0:
        message = f"{name} must be a positive finite number, got {shown(value)}."
        raise ValueError(f"{message} {hint}".strip())
    return number


def check_non_negative(
    name: str, values: object, hint: str = "", *, zero: bool = True
) -> np.ndarray:
    """``values`` as a float array if all are finite and >= 0 (> 0 if not ``zero``),
    else ValueError naming the first bad one."""
    array = as_numbers(name, values, hint)
    bad = ~np.isfinite(array) | ((array < 0) if zero else (array <= 0))
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        where = f" at index {first}" if array.ndim else ""
        rule = ">= 0" if zero else "> 0"
        message = f"{name} must be finite and {rule}, got {shown(array.ravel()[first])}{where}."
        raise ValueError(f"{message} {hint}".strip())
    return array


def check_finite_array(name: str, array: np.ndarray) -> None:
    """ValueError naming the first row of ``array`` holding NaN or infinity."""
    if not np.isfinite(array).all():
        row = np.flatnonzero(~np.isfinite(array.reshape(len(array), -1)).all(axis=1))[0]
        raise ValueError(
            f"{name} must be finite, but row {row} is {array[row].tolist()}; "
            "replace NaN/infinite values with real coordinates"
        )


def as_vectors(name: str, values: object, dim: int, count: int) -> np.ndarray:
    """``values`` as a finite float (count, dim) array (one row is repeated), or ValueError."""
    array = np.array(values, dtype=float)
    if array.shape == (dim,):
        array = np.repeat(array[None], count, axis=0)
    if array.shape != (count, dim):
        raise ValueError(f"{name} must have shape ({count}, {dim}), got shape {array.shape}")
    check_finite_array(name, array)
    return array
