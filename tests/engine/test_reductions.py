"""The kernels' sums over the end of a step: the numba kernel's compiled passes give the
numpy kernel's readable results (to rounding), and a NaN or infinity anywhere is seen."""

import numpy as np
import pytest

import msdlab as msd
from msdlab.compiled import reductions
from msdlab.spring_kernel import make_kernel


def test_damping_work_is_the_readable_sum_to_rounding(kernel: str) -> None:
    rng = np.random.default_rng(1)
    masses, v, v_new = (
        rng.random(1000) + 0.5,
        rng.normal(size=(1000, 3)),
        rng.normal(size=(1000, 3)),
    )
    expected = msd.energy.damping_work(masses, v, v_new, 0.99)
    got = make_kernel(kernel).damping_work(masses, v, v_new, 0.99)
    assert got == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("order", ["C", "F"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("where", ["x", "v"])
def test_finite_sees_one_bad_coordinate(kernel: str, bad: float, where: str, order: str) -> None:
    springs = make_kernel(kernel)
    x, v = np.full((50, 3), 1e300, order=order), np.zeros((50, 3), order=order)  # still finite
    assert springs.finite(x, v)
    (x if where == "x" else v)[37, 2] = bad
    assert not springs.finite(x, v)


def test_threads_give_the_same_damping_work(kernel: str) -> None:
    if kernel == "numpy":
        pytest.skip("threads are the numba kernel's")
    rng = np.random.default_rng(2)
    count = 3 * reductions.BLOCK + 17
    masses, v, v_new = (
        rng.random(count) + 0.5,
        rng.normal(size=(count, 3)),
        rng.normal(size=(count, 3)),
    )
    serial = reductions.damping_work(masses, v, v_new, 0.97)
    assert reductions.damping_work_parallel(masses, v, v_new, 0.97) == serial
    assert serial == pytest.approx(msd.energy.damping_work(masses, v, v_new, 0.97), rel=1e-12)
