"""The words of a failing check: numbers that differ are written so that they differ, and a
function that returns nothing is named once for it."""

import pytest

from msdlab.course import feedback


def test_two_numbers_that_differ_are_written_apart():
    assert feedback.apart(1.499992, 1.49999, 6) == ("1.499992", "1.49999")
    assert feedback.apart(1.5, 1.25) == ("1.5", "1.25")
    assert feedback.apart(2.0, 2.0) == ("2", "2")


def test_a_function_that_returns_nothing_is_one_mistake_in_one_line():
    with pytest.raises(feedback.CheckFailed) as failed:
        feedback.as_array(None, "spring_acceleration", (2, 3))
    assert str(failed.value).startswith("spring_acceleration returned None.")
    assert "shape ()" not in str(failed.value)
    assert failed.value.mistake == feedback.no_return("spring_acceleration")
    with pytest.raises(feedback.CheckFailed) as step:
        feedback.returned(None, "DampedVerlet.step")
    assert step.value.mistake.startswith("no return statement: DampedVerlet.step must end")
    assert feedback.returned(0, "particle_count(3)") == 0
