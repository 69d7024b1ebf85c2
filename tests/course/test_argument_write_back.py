"""Through the grading sandbox a function's in-place changes to its arguments reach the
checks as they do in one process; changes that could break the judge fail the call."""

from __future__ import annotations

import numpy as np
import pytest

from msdlab.instructor.judging.sandbox import ArgumentChanged, RemoteImplementation

MUTATING = """
import numpy as np

def scale(x, factor):
    x *= factor
    return float(x.sum())

def poison(x):
    x[...] = np.nan
    x[0] = np.inf
    x[1] = 1e308

def grow(x):
    x.resize(10**6, refcheck=False)

def retype(x):
    x.dtype = np.int64

def keyword(x, *, y):
    y += 1.0

def untouched(x):
    return x * 2
"""


@pytest.fixture(scope="module")
def remote(serve_task) -> RemoteImplementation:
    return serve_task("task1.py", MUTATING)


def test_values_changed_in_place_reach_the_caller(remote):
    x = np.arange(4.0)
    assert remote.task(1).scale(x, 3.0) == 18.0
    assert x.tolist() == [0.0, 3.0, 6.0, 9.0]
    y = np.zeros(2)
    remote.task(1).keyword(np.zeros(1), y=y)
    assert y.tolist() == [1.0, 1.0]


def test_arguments_left_alone_stay_as_they_were(remote):
    x = np.arange(3.0)
    kept = x.copy()
    np.testing.assert_array_equal(remote.task(1).untouched(x), 2 * kept)
    np.testing.assert_array_equal(x, kept)


def test_non_finite_and_huge_values_arrive_as_in_one_process(remote):
    x = np.zeros(3)
    remote.task(1).poison(x)
    assert np.isinf(x[0]) and x[1] == 1e308 and np.isnan(x[2])


@pytest.mark.parametrize("function", ["grow", "retype"])
def test_a_changed_shape_or_dtype_fails_the_call_not_the_judge(remote, function):
    x = np.zeros(3)
    with pytest.raises(ArgumentChanged, match="in place"):
        getattr(remote.task(1), function)(x)
    assert x.shape == (3,) and x.dtype == float and not x.any()
    assert remote.task(1).scale(np.ones(2), 2.0) == 4.0  # the sandbox still answers
