"""Sums over the end of a step: the damping work is the work of its kick, and the kernels'
finiteness checks see a NaN or infinity anywhere."""

import numpy as np
import pytest

import msdlab as msd
from msdlab.compiled import reductions
from msdlab.spring_kernel import make_kernel


def test_damping_work_is_the_work_of_its_kick() -> None:
    """A factor f per step kicks v by (f - 1)·v: its work at the mean of the step's velocities."""
    rng = np.random.default_rng(1)
    masses, v, v_new = rng.random(1000) + 0.5, *rng.normal(size=(2, 1000, 3))
    kick = (0.99 - 1.0) * v
    expected = -msd.energy.contact_work(masses, kick, v, v_new)
    assert msd.energy.damping_work(masses, v, v_new, 0.99) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("order", ["C", "F"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("where", ["x", "v"])
def test_finite_sees_one_bad_coordinate(kernel: str, bad: float, where: str, order: str) -> None:
    springs = make_kernel(kernel)
    x, v = np.full((50, 3), 1e300, order=order), np.zeros((50, 3), order=order)  # still finite
    assert springs.finite(x, v)
    (x if where == "x" else v)[37, 2] = bad
    assert not springs.finite(x, v)


@pytest.mark.parametrize("count", [10, reductions.PARALLEL_MIN_PARTICLES + 1])
@pytest.mark.parametrize("where", ["x", "v"])
def test_finite_sees_a_bad_coordinate_anywhere(count: int, where: str) -> None:
    """The compiled check, on one thread and on the threads: every place is looked at."""
    rng = np.random.default_rng(count)
    x, v = rng.normal(size=(count, 3)), rng.normal(size=(count, 3))
    assert reductions.finite(x, v)
    for row in (0, count // 2, count - 1, *rng.integers(count, size=5)):
        bad = (x if where == "x" else v).copy()
        bad[row, rng.integers(3)] = np.nan
        assert not reductions.finite(*((bad, v) if where == "x" else (x, bad)))


def test_finite_refuses_arrays_of_different_sizes() -> None:
    with pytest.raises(ValueError, match="same shape"):
        reductions.finite(np.zeros((4, 3)), np.zeros((5, 3)))
