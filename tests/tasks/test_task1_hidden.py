"""Instructor-only checks of task 1 (left out of the student release)."""

from __future__ import annotations

import contextlib
from typing import NoReturn

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from msdlab.course.call_limit import time_limit
from msdlab.course.feedback import CheckFailed, as_array, expect, num

import reference_hidden as reference

pytestmark = [pytest.mark.task1, pytest.mark.hidden]


def template_height(y0: float, dt: float, g: float, steps: int) -> float:
    """Height after ``steps`` steps of the template's kernel from rest, no floor."""
    y_old = y = y0
    for _ in range(steps):
        y_old, y = y, y + dt * ((y - y_old) / dt + dt * g)
    return y


@pytest.mark.points(1)
@settings(max_examples=30)
@given(
    steps=st.integers(0, 2000),
    y0=st.floats(-3.0, 5.0),
    dt=st.floats(0.01, 0.5),
    g=st.floats(-0.05, 0.05),
)
def test_height_after_for_any_start(task1, own_numbers, steps, y0, dt, g):
    """height_after agrees with the running template for any steps, height, dt and g."""
    got = float(task1.height_after(steps, y0, dt, g))
    expected = template_height(y0, dt, g, steps)
    defaults = {"y0": own_numbers.bottom, "dt": 0.1, "g": own_numbers.gravity}  # the template's
    constants = {"y0": "ORIGIN[1]", "dt": "DT", "g": "GRAVITY[1]"}
    given_values = {"y0": y0, "dt": dt, "g": g}
    cause = next(
        (
            f"your template's {constants[name]} = {value} used instead of the argument {name}"
            for name, value in defaults.items()
            if given_values[name] != value
            and np.isclose(got, template_height(**{**given_values, name: value}, steps=steps))
        ),
        "the template's recurrence: each step adds g·dt² to the distance moved per step, so "
        "after n steps y = y0 + g dt² (1 + 2 + ... + n)",
    )
    expect(
        abs(got - expected) <= 1e-9 * max(1.0, abs(expected)),
        saw=f"height_after({steps}, {num(y0)}, {num(dt)}, {num(g)}) = {num(got, 6)}, the "
        f"template gives {num(expected, 6)}",
        cause=cause,
    )


@pytest.mark.points(2)
@settings(max_examples=30)
@example(y0=0.01, dt=0.5, g=-0.05)  # a start within one step of the floor: the answer is 1
@example(y0=0.001, dt=0.5, g=-0.05)
@given(
    y0=st.floats(0.01, 5.0),
    dt=st.floats(0.01, 0.5),
    g=st.floats(-0.05, -1e-4),
)
def test_steps_to_floor_for_any_start(task1, y0, dt, g):
    """steps_to_floor(y0, dt, g) agrees with the running template for any height, step and g."""
    got = task1.steps_to_floor(y0, dt, g)
    first = reference.first_floor_contact(y0, dt, g)
    at_boundary = abs(template_height(y0, dt, g, min(int(got), first))) < 1e-9 * y0
    if got in (first - 1, first + 1):
        cause = f"one step {'early' if got < first else 'late'}: the answer is the first n whose "
        cause += "height y0 + g dt² n(n+1)/2 is <= 0"
    else:
        cause = (
            "a formula that only works for the default numbers, or rounding: check the "
            "smallest n with y0 + g dt² n(n+1)/2 <= 0 directly"
        )
    expect(
        got == first or at_boundary,
        saw=f"steps_to_floor({num(y0)}, {num(dt)}, {num(g)}) = {got!r}, but the running "
        f"template first reaches the floor in step {first}",
        cause=cause,
    )


@pytest.mark.points(1)
def test_particle_count_for_any_size(task1):
    """particle_count(n) is n³ for every n from 1 to 40."""
    wrong = [n for n in range(1, 41) if task1.particle_count(n) != n**3]
    expect(
        not wrong,
        saw=f"particle_count(n) is not the number of particles for n = {wrong[:5]}",
        cause="a result that holds for the default N only",
    )


@pytest.mark.points(1)
def test_verlet_step_leaves_its_inputs_alone(task1):
    """verlet_step returns a new array and does not change old or current."""
    rng = np.random.default_rng(3)
    current = rng.standard_normal((5, 3))
    old = current - 0.01
    kept_old, kept_current = old.copy(), current.copy()
    got = as_array(task1.verlet_step(old, current, 0.1, (0.0, -0.001, 0.0)), "verlet_step")
    expected = 2.0 * kept_current - kept_old + np.array([0.0, -0.001, 0.0]) * 0.1**2
    expect(
        got.shape == expected.shape and np.allclose(got, expected, rtol=1e-9, atol=1e-12),
        saw="verlet_step does not return eq. (1.3)'s new positions (see its other checks); "
        "leaving the inputs alone earns a point only together with the step itself",
        cause="an answer that returns zeros, a constant or one of its inputs",
    )
    expect(
        np.array_equal(old, kept_old) and np.array_equal(current, kept_current),
        saw="verlet_step changed the arrays it was given",
        cause="in-place updates such as current *= 2 or old += ...; the caller still needs "
        "x(t) and x(t - dt) (the template rotates its three buffers)",
    )
    expect(got.shape == current.shape, saw=f"verlet_step returned shape {got.shape}")


def answer_within(seconds: float, call: str) -> contextlib.AbstractContextManager[None]:
    """Fail the check if the block runs longer than ``seconds`` (one process only; the
    grading sandbox has its own time limit per call, shorter than this)."""

    def expire() -> NoReturn:
        raise CheckFailed(
            f"{call} did not answer within {seconds:g} s. Usual cause: a search for the "
            "first floor contact that never ends because the inputs were not checked first."
        )

    return time_limit(seconds, expire)


@pytest.mark.points(1)
def test_steps_to_floor_refuses_a_start_on_or_below_the_floor(task1):
    """steps_to_floor needs y0 > 0, g < 0, dt > 0: anything else is refused with ValueError."""
    g = -0.0015  # no student's own acceleration
    cases = (
        (0.0, 0.1, g, "a particle that starts on the floor"),
        (-0.5, 0.1, g, "a particle that starts below the floor"),
        (1.0, 0.1, 0.0, "a particle that does not fall (g = 0)"),
        (1.0, 0.0, g, "a time step of 0"),
    )
    first = reference.first_floor_contact(1.0, 0.1, g)
    got = task1.steps_to_floor(1.0, 0.1, g)
    expect(
        got == first,
        saw=f"steps_to_floor(1.0, 0.1, {g}) = {got!r} where the template first reaches the "
        f"floor in step {first}: refusing bad starts earns a point only together with "
        "counting the good ones",
        cause="an answer that returns a constant, or the refusal without the count",
    )
    for y0, dt, g, what in cases:
        call = f"steps_to_floor({y0}, {dt}, {g})"
        try:
            with answer_within(90.0, call):
                got = task1.steps_to_floor(y0, dt, g)
        except ValueError:
            continue
        except ZeroDivisionError:
            got = "ZeroDivisionError"
        expect(
            False,
            saw=f"{call} gave {got!r} for {what}",
            cause="no check of the inputs: raise ValueError unless y0 > 0, g < 0 and dt > 0, "
            "as the docstring asks (such a particle has no first floor contact)",
        )
