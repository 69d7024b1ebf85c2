"""The edge loop's springs, sorted by their ends: each with its own values, kept until an edit."""

from __future__ import annotations

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.backends import contract
from msdlab.engine.backends import numpy as numpy_backend
from msdlab.engine.backends.layout import Layout
from msdlab.engine.backends.numba import NumbaKernel
from msdlab.engine.backends.numba.kernel import sorted_edges

RTOL = 1e-12


@pytest.fixture(autouse=True)
def _once(kernel: str) -> None:
    """These tests look inside the numba kernel and compare it with the numpy one themselves."""
    if kernel != "numba":
        pytest.skip("tests the numba kernel's edge loop")


def shuffled_body(seed: int = 0) -> msd.Body:
    """A shaken, moving 5×4×6 grid whose springs were added in a random order (no gather)."""
    rng = np.random.default_rng(seed)
    grid = msd.Body.grid((5, 4, 6), spacing=0.1, stiffness=40.0, neighbours=(1, 2, 3))
    order = rng.permutation(grid.n_springs)
    pairs = np.stack([grid.edges().a[order], grid.edges().b[order]], axis=1)
    body = msd.Body.from_arrays(
        grid.positions + rng.normal(scale=0.02, size=grid.positions.shape),
        pairs,
        velocities=rng.normal(size=grid.positions.shape),
        stiffness=40.0,
        rest_lengths=grid.edges().rest_lengths[order],
    )
    return body


def forces_by(
    kernel: contract.SpringKernel, body: msd.Body, springs=None, layout: Layout | None = None
) -> tuple:
    """The spring forces, largest stretch and dashpot power by ``kernel``, given ``layout``
    (a fresh one of ``body`` if None)."""
    layout = Layout(body) if layout is None else layout
    out = np.zeros_like(body.positions)
    stretch, power = kernel.spring_forces(
        Layout(body), body.positions, body.velocities, out, springs
    )
    return out, stretch, power


def assert_same(actual: tuple, expected: tuple) -> None:
    """Bit for bit: the same forces, largest stretch and dashpot power."""
    np.testing.assert_array_equal(actual[0], expected[0])
    assert actual[1:] == expected[1:]


def assert_close_to_numpy(body: msd.Body, kernel: NumbaKernel, springs=None) -> None:
    expected = forces_by(numpy_backend.NumpyKernel(), body, springs)
    actual = forces_by(kernel, body, springs)
    scale = np.abs(expected[0]).max()
    np.testing.assert_allclose(actual[0], expected[0], rtol=RTOL, atol=RTOL * scale)
    assert actual[1] == pytest.approx(expected[1], rel=RTOL)
    assert actual[2] == pytest.approx(expected[2], rel=RTOL, abs=RTOL * scale)


def test_sorted_springs_keep_each_springs_values() -> None:
    body = shuffled_body()
    body.set_springs(slice(None, None, 4), damping=0.3)
    a, b, k, rest, c = sorted_edges(body.edges(), len(body))
    assert np.all(np.diff(a.astype(np.int64)) >= 0)  # sorted by the first end
    order = np.lexsort((body.edges().b, body.edges().a))
    np.testing.assert_array_equal(b, body.edges().b[order])
    for sorted_values, values in zip((k, rest, c), body.edges().values()):
        np.testing.assert_array_equal(sorted_values, values[order])
    assert_close_to_numpy(body, NumbaKernel())


def sorted_body() -> msd.Body:
    """`shuffled_body` with its springs added sorted by their ends, as the edge loop takes them."""
    shuffled = shuffled_body(3)
    order = np.lexsort((shuffled.edges().b, shuffled.edges().a))
    pairs = np.stack([shuffled.edges().a[order], shuffled.edges().b[order]], axis=1)
    return msd.Body.from_arrays(
        shuffled.positions, pairs, rest_lengths=shuffled.edges().rest_lengths[order]
    )


def test_springs_in_order_are_read_from_the_body() -> None:
    """Springs already sorted: the loop reads the body's own arrays, no copies."""
    body = sorted_body()
    _, _, k, _, _ = sorted_edges(body.edges(), len(body))
    assert np.shares_memory(k, body.edges().values()[0])
    body.set_springs([4], stiffness=7.0)
    assert_close_to_numpy(body, NumbaKernel())


def test_reading_the_values_keeps_the_layout_and_editing_counts() -> None:
    """Reading a spring array, or holding it, is no edit: the layout (and the kernel's sorted
    springs) is kept. The arrays are read-only; an edit goes through `Body.set_springs` (or a
    whole array) and counts."""
    body = shuffled_body(3)
    dynamics = msd.Dynamics(body, kernel="numba")
    kernel = dynamics.springs
    kept = dynamics.layout
    before = forces_by(kernel, body, layout=kept)
    held = body.edges().rest_lengths
    assert dynamics.layout is kept
    assert_same(forces_by(kernel, body, layout=dynamics.layout), before)
    with pytest.raises(ValueError, match="read-only"):
        held[6] = 1.0
    for edit in (
        lambda: body.set_springs([6], rest_lengths=held[6] * 1.1),
        lambda: body.set_springs(rest_lengths=body.edges().rest_lengths * 1.01),
        lambda: body.set_springs(slice(3, 5), stiffness=7.0),
        lambda: body.set_springs(damping=0.0),
    ):
        version = body.version
        edit()
        assert body.version == version + 1
        assert dynamics.layout is not kept
        kept = dynamics.layout
        assert_same(forces_by(kernel, body, layout=kept), forces_by(NumbaKernel(), body))
    version = body.version
    _ = (
        body.edges().stiffness * 2.0,
        held.sum(),
        body.edges().values()[0][3],
        np.unique(body.edges().stiffness),
    )
    assert body.version == version


@pytest.mark.parametrize("threaded", [False, True])
def test_springs_edited_between_steps(threaded: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """Springs edited between steps count at the next step, as if the body had been built
    with the new values."""
    if threaded:
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_SPRINGS", 0)
    body = shuffled_body(2)
    sim = msd.Simulation(body, msd.Verlet(0.01), dt=1e-3, kernel="numba")
    for step in range(3):
        sim.step()
        body.set_springs([step], stiffness=90.0 + step)
        body.set_springs([5 * step], rest_lengths=body.edges().rest_lengths[5 * step] * 1.25)
        body.set_springs([7 * step], damping=0.2)
        laid = sim.dynamics.layout
        assert_same(
            forces_by(sim.dynamics.springs, body, layout=laid), forces_by(NumbaKernel(), body)
        )
    body.springs[9].stiffness = 3.0  # and through a Spring object
    laid = sim.dynamics.layout
    assert_same(forces_by(sim.dynamics.springs, body, layout=laid), forces_by(NumbaKernel(), body))


def test_springs_subset_in_the_bodys_order() -> None:
    body = shuffled_body(4)
    body.set_springs(slice(None, None, 3), damping=0.4)
    kernel = NumbaKernel()
    forces_by(kernel, body)  # the sorted list is built, and must not be used
    touching = body.springs_touching(np.array([3, 8, 40]))
    assert_close_to_numpy(body, kernel, touching)
    assert_close_to_numpy(body, kernel, touching[::-1])
    empty = np.zeros(0, dtype=np.int64)
    assert forces_by(kernel, body, empty)[1:] == (0.0, 0.0)
