"""The kernels' sums over the end of a step: the numba kernel's compiled passes give the
numpy kernel's readable results (to rounding), and a NaN or infinity anywhere is seen."""

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.backends.choice import make_kernel
from msdlab.engine.backends.numba import kernel as numba_kernel
from msdlab.engine.equations import damping_work


def test_damping_work_is_the_readable_sum_to_rounding(kernel: str) -> None:
    rng = np.random.default_rng(1)
    masses, v, v_new = (
        rng.random(1000) + 0.5,
        rng.normal(size=(1000, 3)),
        rng.normal(size=(1000, 3)),
    )
    expected = damping_work(masses, v, v_new, 0.99)
    body = msd.Body.from_arrays(np.zeros((1000, 3)), masses=masses)
    got = msd.Dynamics(body, kernel=kernel).springs.damping_work(masses, v, v_new, 0.99)
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


@pytest.mark.parametrize("count", [10, numba_kernel.PARALLEL_MIN_PARTICLES + 1])
@pytest.mark.parametrize("where", ["x", "v"])
def test_finite_sees_a_bad_coordinate_anywhere(count: int, where: str) -> None:
    """The compiled check, on one thread and on the threads: every place is looked at."""
    rng = np.random.default_rng(count)
    x, v = rng.normal(size=(count, 3)), rng.normal(size=(count, 3))
    assert numba_kernel.finite(x, v)
    for row in (0, count // 2, count - 1, *rng.integers(count, size=5)):
        bad = (x if where == "x" else v).copy()
        bad[row, rng.integers(3)] = np.nan
        assert not numba_kernel.finite(*((bad, v) if where == "x" else (x, bad)))


def test_finite_refuses_arrays_of_different_sizes() -> None:
    with pytest.raises(ValueError, match="same shape"):
        numba_kernel.finite(np.zeros((4, 3)), np.zeros((5, 3)))


@pytest.mark.parametrize(
    "count", [3 * numba_kernel.BLOCK + 17, numba_kernel.PARALLEL_MIN_PARTICLES + 5]
)
def test_damping_work_sums_its_blocks_in_order(count: int) -> None:
    """One thread or several (past `PARALLEL_MIN_PARTICLES`): the blocks in the same order."""
    rng = np.random.default_rng(count)
    masses, v, v_new = (
        rng.random(count) + 0.5,
        rng.normal(size=(count, 3)),
        rng.normal(size=(count, 3)),
    )
    total = 0.0
    for block in range(-(-count // numba_kernel.BLOCK)):
        total += numba_kernel._kick_works(masses, v, v_new, 0.97, block)
    got = numba_kernel.damping_work(masses, v, v_new, 0.97)
    assert got == -total
    assert got == pytest.approx(damping_work(masses, v, v_new, 0.97), rel=1e-12)
