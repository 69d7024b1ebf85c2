"""A grid body keeps its springs per offset (`lattice.GridSprings`) until they are laid out:
the same springs, the same steps, and no per-spring memory while only the kernel needs them."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import msdlab as msd
from msdlab.kernels import NumpyKernel
from msdlab.lattice import grid_pairs, neighbour_offsets
from msdlab.spring_kernel import make_kernel


def jelly(shape: tuple[int, ...], damping: float = 0.0, seed: int = 0) -> msd.Body:
    """A grid with springs to the neighbours at squared distances 1, 2 (and 3 or 4), jiggled."""
    neighbours = (1, 2, 3) if len(shape) == 3 else (1, 2, 4)
    body = msd.Body.grid(
        shape, spacing=0.1, stiffness=300.0, neighbours=neighbours, damping=damping
    )
    rng = np.random.default_rng(seed)
    body.positions[:] += 0.01 * rng.standard_normal(body.positions.shape)
    body.velocities[:] = rng.standard_normal(body.velocities.shape)
    return body


def laid_out(body: msd.Body) -> msd.Body:
    """A copy of ``body`` whose springs are per-spring arrays."""
    twin = body.copy()
    twin.lay_out_springs()
    return twin


def kept_per_offset(body: msd.Body) -> bool:
    return body.grid_springs is not None


@pytest.mark.parametrize("shape", [(4, 3, 5), (6, 5)])
def test_reading_the_ends_lays_out_the_grids_springs(shape: tuple[int, ...]) -> None:
    """Stiffness and dashpots read as one value for all springs (no memory per spring, no
    lay-out); reading the ends or rest lengths lays the springs out, same order, same values."""
    body = msd.Body.grid(shape, spacing=0.5, stiffness=7.0, neighbours=(1, 2, 4), damping=0.2)
    assert kept_per_offset(body)
    version = body.version
    offsets = neighbour_offsets(len(shape), (1, 2, 4))
    pairs, kinds = grid_pairs(shape, offsets)
    assert body.n_springs == len(pairs)
    for values, value in ((body.stiffness, 7.0), (body.spring_damping, 0.2)):
        assert values.shape == (len(pairs),) and values.strides == (0,) and np.all(values == value)
    assert kept_per_offset(body)
    assert np.array_equal(body.spring_a, pairs[:, 0]) and np.array_equal(body.spring_b, pairs[:, 1])
    assert body.grid_springs is None
    rest = 0.5 * np.sqrt((offsets**2).sum(axis=1))[kinds]
    assert np.array_equal(body.rest_lengths, rest)
    assert np.all(body.stiffness == 7.0) and np.all(body.spring_damping == 0.2)
    assert body.version == version  # nothing changed


def test_the_springs_kept_per_offset_are_the_springs(kernel: str) -> None:
    """Forces, energy and dashpot power of a grid kept per offset are those of its springs
    laid out, in 2-D and 3-D, with and without dashpots."""
    for body in (jelly((5, 4, 6)), jelly((5, 4, 6), 0.4), jelly((9, 7), 0.4)):
        twin = laid_out(body)
        x, v = body.positions, body.velocities
        springs = make_kernel(kernel)
        forces = np.zeros_like(x)
        stretch, power = springs.spring_forces(body, x, v, forces, None)
        energy = springs.elastic_energy(body, x, None)
        reference = NumpyKernel()
        expected = np.zeros_like(x)
        assert (stretch, power) == pytest.approx(
            reference.spring_forces(twin, x, v, expected), rel=1e-12
        )
        np.testing.assert_allclose(forces, expected, rtol=1e-12, atol=1e-12)
        assert energy == pytest.approx(reference.elastic_energy(twin, x), rel=1e-12)


@pytest.mark.parametrize("threads", [False, True])
def test_a_run_matches_the_laid_out_body(
    kernel: str, threads: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same steps bit for bit, and the same ledger, with the springs per offset or laid
    out; on the numba kernel the springs are never laid out for the run."""
    if threads and kernel == "numpy":
        pytest.skip("threads are the numba kernel's")
    if threads:
        monkeypatch.setattr("msdlab.compiled.kernel.PARALLEL_MIN_SPRINGS", 0)
        monkeypatch.setattr("msdlab.compiled.kernel.PARALLEL_MIN_GATHERED", 0)
        monkeypatch.setattr("msdlab.compiled.kernel.PARALLEL_MIN_PARTICLES", 0)
    trajectories = []
    for body in (jelly((6, 5, 7), 0.3), laid_out(jelly((6, 5, 7), 0.3))):
        body.positions[:, 1] += 0.05
        forces = [msd.Gravity((0, -9.81, 0)), msd.Ground()]
        sim = msd.Simulation(body, msd.Verlet(0.01), dt=1e-3, forces=forces)
        trajectories.append(sim.run(steps=40, record_velocities=True))
        if kernel == "numba" and len(trajectories) == 1:
            assert kept_per_offset(body)
    kept, arrays = trajectories
    assert np.array_equal(kept.positions, arrays.positions)
    assert np.array_equal(kept.velocities, arrays.velocities)
    np.testing.assert_allclose(kept.energies.total, arrays.energies.total, rtol=1e-12)
    np.testing.assert_allclose(kept.energies.elastic, arrays.energies.elastic, rtol=1e-12)
    for name in ("dashpot", "integrator", "ground"):
        dissipated = kept.energies.dissipated[name], arrays.energies.dissipated[name]
        np.testing.assert_allclose(*dissipated, rtol=1e-12, atol=1e-15)


def test_edits_lay_out_the_springs_and_count(kernel: str) -> None:
    """Editing all springs of a grid alike keeps them per offset; editing one lays them out;
    both count (`Body.version`) and change the forces at once."""
    body = jelly((4, 4, 4))
    version = body.version
    body.stiffness = 400.0
    assert kept_per_offset(body) and body.version == version + 1
    assert body.grid_springs.stiffness == 400.0 and np.all(body.stiffness == 400.0)
    sim = msd.Simulation(body, msd.SymplecticEuler(), dt=1e-4)
    sim.step()  # the numpy kernel lays the springs out; the numba kernel gathers by offset
    version = body.version
    body.set_springs([5], stiffness=900.0)
    assert body.grid_springs is None and body.version == version + 1
    assert body.stiffness[5] == 900.0 and body.stiffness[4] == 400.0
    x, v = body.positions, body.velocities
    forces, expected = np.zeros_like(x), np.zeros_like(x)
    sim.dynamics.springs.spring_forces(body, x, v, forces, None)
    NumpyKernel().spring_forces(body, x, v, expected)
    np.testing.assert_allclose(forces, expected, rtol=1e-12, atol=1e-12)
    body.spring_damping = 0.5  # a whole array, checked
    assert np.all(body.spring_damping == 0.5)
    with pytest.raises(ValueError, match="damping"):
        body.spring_damping = -1.0


def test_copy_pickle_and_growth_keep_the_springs() -> None:
    body = jelly((3, 4, 5), 0.1)
    for twin in (body.copy(), pickle.loads(pickle.dumps(body))):
        assert kept_per_offset(twin) and twin.n_springs == body.n_springs
        assert np.array_equal(twin.spring_b, laid_out(body).spring_b)
    grown = body.copy()
    grown.add_particles([[5.0, 5.0, 5.0]])
    assert grown.n_springs == body.n_springs and grown.grid_springs is not None
    grown.add_springs([[0, len(grown) - 1]], stiffness=2.0)
    assert grown.n_springs == body.n_springs + 1 and grown.stiffness[-1] == 2.0
    assert np.array_equal(grown.spring_a[:-1], laid_out(body).spring_a)
