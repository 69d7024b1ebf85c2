"""A submission's experiments run once per setting, and a cause is looked for only on failure."""

from __future__ import annotations

from types import ModuleType

import pytest

from msdlab.course.experiments import cube_ratio
from msdlab.course.feedback import CheckFailed, Recognised, expect


def counting_task(results):
    """A task module whose drop_rotated_cube returns ``results`` one call after the other (a
    stateful submission) and records its calls."""
    calls = []

    def drop_rotated_cube(angle, axis, neighbours, steps=1500):
        calls.append((axis, angle, neighbours, steps))
        result = results[len(calls) - 1]
        if isinstance(result, Exception):
            raise result
        return result

    task = ModuleType("task3")
    task.drop_rotated_cube = drop_rotated_cube
    return task, calls


def test_each_setting_runs_once_and_its_checks_share_the_first_result():
    task, calls = counting_task([0.2, 0.95, 0.7, 0.4])
    assert cube_ratio(task, 45.0, (0.0, 0.0, 1.0), (1,)) == 0.2
    assert cube_ratio(task, 45.0, (0.0, 0.0, 1.0), (1, 2, 3)) == 0.95
    assert cube_ratio(task, 45.0, (0.0, 0.0, 1.0), (1,), steps=1) == 0.7
    assert cube_ratio(task, 45.0, (0.0, 0.0, 1.0), (1,)) == 0.2  # not 0.4: run once
    assert calls == [
        ((0.0, 0.0, 1.0), 45.0, (1,), 1500),
        ((0.0, 0.0, 1.0), 45.0, (1, 2, 3), 1500),
        ((0.0, 0.0, 1.0), 45.0, (1,), 1),
    ]
    other, other_calls = counting_task([0.5])
    assert cube_ratio(other, 45.0, (0.0, 0.0, 1.0), (1,)) == 0.5  # another submission runs it
    assert len(other_calls) == 1


def test_a_failing_run_is_not_kept_each_check_sees_its_failure():
    task, calls = counting_task([ZeroDivisionError("division by zero"), "not a number", 0.3])
    with pytest.raises(ZeroDivisionError):
        cube_ratio(task, 30.0, (1.0, 0.0, 0.0), (1,))
    with pytest.raises(ValueError):
        cube_ratio(task, 30.0, (1.0, 0.0, 0.0), (1,))
    assert cube_ratio(task, 30.0, (1.0, 0.0, 0.0), (1,)) == 0.3
    assert len(calls) == 3


def test_a_cause_given_as_a_function_is_looked_for_only_when_the_check_fails():
    looked = []

    def cause():
        looked.append(True)
        return Recognised("counting from 0")

    expect(True, saw="the answer is 42", cause=cause)
    assert not looked
    with pytest.raises(CheckFailed) as failed:
        expect(False, saw="the answer is 41", cause=cause)
    assert looked == [True]
    assert failed.value.mistake == "counting from 0"
    assert "the answer is 41." in str(failed.value)
    with pytest.raises(CheckFailed, match=r"Usual cause: an off-by-one\.$"):
        expect(False, saw="the answer is 41", cause=lambda: "an off-by-one")
