"""The lattice loop (gather) and the edge loop of the numba kernel agree to rounding; the
spring set's kind chooses the loop."""

from __future__ import annotations

import numpy as np
import pytest

import msdlab as msd
import msdlab.engine.backends.numba.kernel as compiled_kernel
from msdlab.engine.backends import numpy as numpy_backend
from msdlab.engine.backends.contract import SpringKernel
from msdlab.engine.backends.layout import Layout
from msdlab.engine.backends.numba import NumbaKernel

RTOL = 1e-12


@pytest.fixture(autouse=True)
def _once(kernel: str) -> None:
    """These tests compare both numba backends with the numpy reference themselves."""
    if kernel != "numba":
        pytest.skip("compares the numba backends with the numpy kernel directly")


def shaken_grid(shape: tuple[int, ...], neighbours: tuple[int, ...], damping: float) -> msd.Body:
    """A grid with uniform springs per offset, moved off rest and moving."""
    rng = np.random.default_rng(1)
    body = msd.Body.grid(shape, spacing=0.1, stiffness=40.0, neighbours=neighbours, damping=damping)
    body.positions[:] += rng.normal(scale=0.02, size=body.positions.shape)
    body.velocities[:] = rng.normal(size=body.positions.shape)
    return body


def laid_out(body: msd.Body) -> msd.Body:
    """A copy of ``body`` whose springs are an edge list (the edge loop's)."""
    twin = body.copy()
    twin.springs_as_edges()
    return twin


def gathers(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The names of the gather loops `NumbaKernel` runs from now on, as they are run."""
    ran: list[str] = []
    for name in ("gather_serial", "gather_parallel"):
        loop = getattr(compiled_kernel, name)
        monkeypatch.setattr(
            f"msdlab.engine.backends.numba.kernel.{name}",
            lambda *args, name=name, loop=loop: ran.append(name) or loop(*args),
        )
    return ran


def forces_by(kernel: SpringKernel, body: msd.Body) -> tuple[np.ndarray, float, float]:
    out = np.zeros_like(body.positions)
    stretch, power = kernel.spring_forces(Layout(body), body.positions, body.velocities, out, None)
    return out, stretch, power


def assert_agree(body: msd.Body, numba_kernel: NumbaKernel) -> None:
    expected, stretch, power = forces_by(numpy_backend.NumpyKernel(), body)
    forces_by(numba_kernel, body)  # a second call must not see the first one's forces
    actual, actual_stretch, actual_power = forces_by(numba_kernel, body)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(actual, expected, rtol=RTOL, atol=RTOL * scale)
    assert actual_stretch == pytest.approx(stretch, rel=RTOL)
    assert actual_power == pytest.approx(power, rel=RTOL, abs=RTOL * scale)


@pytest.mark.parametrize(
    ("shape", "neighbours"),
    [
        ((5, 4, 6), (1, 2, 3)),
        ((6, 5, 4), (1, 2, 3, 4)),
        ((7, 5), (1, 2)),
        ((1, 1, 5), (1,)),
        ((4, 5, 6), (1,)),  # every triple holds one spring
        ((170, 100), (1, 2)),  # 2-D: five blocks of rows, taken as planes are in 3-D
    ],
)
@pytest.mark.parametrize("damping", [0.0, 0.3])
@pytest.mark.parametrize("threaded", [False, True])
def test_gather_matches_edge_loop_and_numpy(
    shape: tuple[int, ...],
    neighbours: tuple[int, ...],
    damping: float,
    threaded: bool,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    if threaded:
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_SPRINGS", 0)
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_GATHERED", 0)
    body = shaken_grid(shape, neighbours, damping)
    ran = gathers(monkeypatch)
    assert_agree(body, NumbaKernel())
    assert ran and set(ran) == {"gather_parallel" if threaded else "gather_serial"}
    ran.clear()
    assert_agree(laid_out(body), NumbaKernel())
    assert not ran  # an edge list: the edge loop


@pytest.mark.parametrize(("shape", "neighbours"), [((9, 4, 6), (1, 2, 3)), ((170, 100), (1, 2))])
@pytest.mark.parametrize("damping", [0.0, 0.3])
def test_threads_give_the_same_sums_as_one_thread(
    shape: tuple[int, ...],
    neighbours: tuple[int, ...],
    damping: float,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    body = shaken_grid(shape, neighbours, damping)
    one_thread = forces_by(NumbaKernel(), body)
    monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_SPRINGS", 0)
    monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_GATHERED", 0)
    threads = forces_by(NumbaKernel(), body)
    np.testing.assert_array_equal(threads[0], one_thread[0])
    assert threads[1:] == one_thread[1:]


def test_coincident_ends_exert_no_force() -> None:
    body = shaken_grid((3, 3, 3), (1, 2, 3), 0.2)
    body.positions[4] = body.positions[5]  # particles 4 and 5 share a spring
    forces, _, power = forces_by(NumbaKernel(), body)
    assert np.isfinite(forces).all() and np.isfinite(power)
    assert_agree(body, NumbaKernel())


def test_the_kind_of_spring_set_chooses_the_loop(monkeypatch: pytest.MonkeyPatch) -> None:
    """A lattice is gathered; the same springs as an edge list, in grid order or not, go
    through the edge loop, and so does a lattice once its springs are made an edge list."""
    ran = gathers(monkeypatch)
    grid = shaken_grid((4, 3, 5), (1, 2, 3), 0.0)
    kernel = NumbaKernel()
    forces_by(kernel, grid)
    assert ran == ["gather_serial"]
    edges = grid.edges()
    pairs = np.stack([edges.a, edges.b], axis=1)
    for order in (slice(None), slice(None, None, -1)):
        forces_by(NumbaKernel(), msd.Body.from_arrays(grid.positions, pairs[order]))
    grid.springs_as_edges()
    forces_by(kernel, grid)
    assert ran == ["gather_serial"]


@pytest.mark.parametrize("how", ["set_springs", "spring object"])
def test_edits_of_single_springs_go_through_the_edge_loop(how: str) -> None:
    body = shaken_grid((4, 4, 4), (1, 2, 3), 0.0)
    kernel = NumbaKernel()
    assert_agree(body, kernel)
    held = body.springs_as_edges().stiffness
    if how == "set_springs":
        body.set_springs([17], stiffness=90.0)
    else:
        body.springs[17].stiffness = 90.0
    assert held[17] == 90.0
    assert_agree(body, kernel)  # the edit counts at once
    with pytest.raises(ValueError, match="read-only"):
        held[17] = 40.0  # the arrays change only through the body
    body.set_springs(damping=0.5)  # dashpots included
    assert_agree(body, kernel)


@pytest.mark.parametrize("threaded", [False, True])
def test_simulation_on_the_gather_follows_the_edge_loop(
    threaded: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """200 steps of a grid falling onto the ground, SymplecticEuler and damped Verlet
    (threaded: the spring forces and the update, on the gather and on the edge loop)."""
    if threaded:
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_SPRINGS", 0)
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_GATHERED", 0)
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_PARTICLES", 0)
    runs = []
    for gathered in (True, False):
        for integrator in (msd.SymplecticEuler(), msd.Verlet(0.01)):
            body = shaken_grid((4, 5, 3), (1, 2, 3), 0.1)
            body = body if gathered else laid_out(body)
            body.positions[:, 1] += 0.05
            forces = [msd.Gravity((0, -9.81, 0)), msd.Ground()]
            sim = msd.Simulation(body, integrator, dt=1e-3, forces=forces, kernel="numba")
            sim.run(steps=200)
            runs.append((body.positions.copy(), dict(sim.dissipated)))
    for (x_gather, booked_gather), (x_edge, booked_edge) in zip(runs[:2], runs[2:]):
        np.testing.assert_allclose(x_gather, x_edge, rtol=0, atol=1e-11)
        for name, energy in booked_edge.items():
            assert booked_gather[name] == pytest.approx(energy, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("threaded", [False, True])
def test_shuffled_springs_sorted_for_the_edge_loop(
    threaded: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Springs in a random order with random values: the sorted edge loop sees every edit."""
    if threaded:
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_SPRINGS", 0)
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_GATHERED", 0)
    grid = shaken_grid((4, 3, 5), (1, 2, 3), 0.0)
    order = np.random.default_rng(2).permutation(grid.n_springs)
    pairs = np.stack([grid.edges().a[order], grid.edges().b[order]], axis=1)
    body = msd.Body.from_arrays(
        grid.positions, pairs, velocities=grid.velocities, stiffness=grid.edges().stiffness[order]
    )
    body.set_springs(slice(None, None, 3), damping=0.4)
    kernel = NumbaKernel()
    assert_agree(body, kernel)
    body.set_springs([5], stiffness=123.0)
    assert_agree(body, kernel)
    body.set_springs([7], rest_lengths=body.edges().rest_lengths[7] * 1.5)
    assert_agree(body, kernel)
    touching = body.springs_touching(np.array([3, 8]))
    assert kernel.elastic_energy(Layout(body), body.positions, touching) == pytest.approx(
        numpy_backend.elastic_energy(body, body.positions, touching), rel=RTOL
    )
