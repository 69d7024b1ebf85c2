"""Messages of failing checks: what the check saw, in physics terms, and what usually causes it.

A check states its expectation with `expect`::

    expect(
        drift < 0.01,
        saw=f"total energy grew {percent(drift)} in {steps} steps at dt = {num(dt)}",
        cause="forces that are not equal and opposite, or dt above the stable limit",
    )

and the student reads "total energy grew 40 % in 200 steps at dt = 0.1. Usual
cause: ...". A cause the check recognised by computing it (`Recognised`, what
`matching_variant` returns) is said as the student's mistake, and the report
names it once for every check that recognised it. `CheckFailed` is an
`AssertionError`, so pytest reports it as a failed check, not as an error in the
check itself.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from .report import MISTAKE_SENTENCE


class CheckFailed(AssertionError):
    """A check saw wrong physics; the message says what it saw and the usual cause.

    ``mistake`` is the typical mistake the check recognised in the result ('' if none):
    the report names it once for all the checks that recognised it.
    """

    def __init__(self, message: str, mistake: str = "") -> None:
        super().__init__(message)
        self.mistake = mistake


class Recognised(str):
    """A cause the check computed and found equal to the result (`matching_variant`): not the
    usual cause of such a failure but the student's mistake, said as such."""


def expect(condition: object, saw: str, cause: str | Callable[[], str] = "") -> None:
    """Raise `CheckFailed` unless ``condition`` holds: "<saw>. Usual cause: <cause>.", or for a
    `Recognised` cause "<saw>. Your result is exactly what this mistake gives: <cause>.".

    A cause that takes work to find (running the submission again) is given as a function
    of no arguments, called only when the check fails."""
    if not bool(condition):
        message = saw.rstrip(". ") + "."
        cause = cause() if callable(cause) else cause
        if isinstance(cause, Recognised):
            raise CheckFailed(f"{message} {MISTAKE_SENTENCE.format(cause)}", mistake=str(cause))
        if cause:
            message += f" Usual cause: {cause.rstrip('. ')}."
        raise CheckFailed(message)


def num(value: float, digits: int = 3) -> str:
    """A number with ``digits`` significant digits, e.g. 0.000123 -> '0.000123'."""
    value = float(value)
    if not np.isfinite(value):
        return str(value)
    return f"{value:.{digits}g}" if value != 0 else "0"  # no "-0"


def apart(first: float, second: float, digits: int = 3) -> tuple[str, str]:
    """Two different numbers written with at least ``digits`` significant digits and as many
    more as it takes to tell them apart: (1.499992, 1.49999) -> ('1.499992', '1.49999')."""
    for more in range(digits, 18):
        shown = num(first, more), num(second, more)
        if shown[0] != shown[1] or float(first) == float(second):
            return shown
    return shown


def vec(values: Sequence[float] | np.ndarray, digits: int = 3) -> str:
    """A short vector, e.g. '(0.1, -0.002, 0)'."""
    return "(" + ", ".join(num(v, digits) for v in np.ravel(values)) + ")"


def percent(fraction: float) -> str:
    """A fraction as a percentage, e.g. 0.4 -> '40 %', 2e-5 -> '0.002 %', 650 -> '65000 %',
    1e83 -> '1e+85 %' (scientific notation from a million per cent on)."""
    value = 100.0 * float(fraction)
    if abs(value) >= 1e6 or not np.isfinite(value):
        return f"{num(value, 2)} %"
    return f"{value:.0f} %" if abs(value) >= 100 else f"{num(value, 2)} %"


def relative_error(got: np.ndarray, expected: np.ndarray) -> float:
    """max |got - expected| relative to max |expected| (absolute if expected is all zero)."""
    got, expected = np.asarray(got, dtype=float), np.asarray(expected, dtype=float)
    scale = float(np.max(np.abs(expected), initial=0.0))
    error = float(np.max(np.abs(got - expected), initial=0.0))
    return error / scale if scale > 0 else error


def returned(value: object, what: str) -> object:
    """``value``, the result of the student's ``what``; a `CheckFailed` naming the mistake once
    where it is None (the function returns nothing: a ``return`` is missing)."""
    if value is None:
        mistake = no_return(what.split("(")[0].split()[0])
        raise CheckFailed(f"{what} returned None. {MISTAKE_SENTENCE.format(mistake)}", mistake)
    return value


def no_return(function: str) -> Recognised:
    """The mistake of a student's ``function`` that returns None, in the words every check
    names it with (so the report names it once)."""
    return Recognised(f"no return statement: {function} must end with return and its result")


def as_array(value: object, what: str, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """``value`` as a float array, or a `CheckFailed` saying what came back instead."""
    returned(value, what)
    expect(
        not np.iscomplexobj(value),
        saw=f"{what} returned complex numbers",
        cause="a square root or power of a negative number; positions, forces and "
        "accelerations are real",
    )
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise CheckFailed(
            f"{what} returned {type(value).__name__}, not an array of numbers"
        ) from None
    if shape is not None and array.shape != shape:
        raise CheckFailed(f"{what} returned an array of shape {array.shape}, expected {shape}")
    expect(
        np.all(np.isfinite(array)),
        saw=f"{what} returned NaN or infinite values",
        cause="dividing by a zero spring length or a zero time step",
    )
    return array


def expect_nontrivial(got: np.ndarray, given: np.ndarray, what: str) -> None:
    """Fail if ``got`` (one row per particle) is all zeros, one row repeated, or ``given``.

    A property check calls it first: such answers satisfy many properties (no net force,
    rotation invariance, energy conservation) without any physics.
    """
    got, given = np.asarray(got, dtype=float), np.asarray(given, dtype=float)
    rows = got.reshape(-1, got.shape[-1]) if got.ndim else got.reshape(1, 1)
    kind = (
        "all zeros"
        if not np.any(got)
        else "its input unchanged"
        if got.shape == given.shape and np.array_equal(got, given)
        else "the same vector for every particle"
        if len(rows) > 1 and np.all(rows == rows[0])
        else None
    )
    expect(
        kind is None,
        saw=f"{what} returns {kind}: the property checked here holds trivially for such an "
        "answer, so it earns no point",
        cause="an answer not computed from the springs; sum eq. (1.2) over each particle's "
        "neighbours",
    )


def matching_variant(
    got: np.ndarray, variants: dict[str, np.ndarray], rtol: float = 1e-6
) -> Recognised | None:
    """The name of the first variant (a typical mistake, computed by the check) equal to ``got``."""
    got = np.asarray(got, dtype=float)
    for name, values in variants.items():
        values = np.asarray(values, dtype=float)
        if values.shape == got.shape and relative_error(got, values) < rtol:
            return Recognised(name)
    return None


def grid_place(index: Sequence[int], shape: Sequence[int]) -> str:
    """Where particle ``index`` sits in a grid: 'corner particle (0, 0, 0)', 'interior ...'."""
    borders = sum(1 for i, n in zip(index, shape) if n > 1 and i in (0, n - 1))
    kind = ("interior", "face", "edge", "corner")[min(borders, 3)]
    return f"{kind} particle {tuple(int(i) for i in index)}"
