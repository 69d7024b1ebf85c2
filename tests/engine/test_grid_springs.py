"""A grid body's springs are a lattice (`lattice.LatticeSprings`): values per neighbour offset,
the same springs, forces and steps as those springs laid out as an edge list, and no memory
per spring unless asked for (`Body.edges`, `Body.springs_as_edges`)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.backends.choice import make_kernel
from msdlab.engine.backends.layout import Layout
from msdlab.engine.backends.numpy import NumpyKernel
from msdlab.engine.model.lattice import LatticeSprings, grid_pairs, neighbour_offsets
from msdlab.engine.model.springs import EdgeSprings


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
    """A copy of ``body`` whose springs are an edge list."""
    twin = body.copy()
    twin.springs_as_edges()
    return twin


def is_lattice(body: msd.Body) -> bool:
    return isinstance(body.spring_set, LatticeSprings)


@pytest.mark.parametrize("shape", [(4, 3, 5), (6, 5)])
def test_a_grid_keeps_one_value_per_offset_and_lays_out_only_when_asked(
    shape: tuple[int, ...],
) -> None:
    """The values are one per offset, read as they are; `edges` lays the springs out (same
    order as `grid_pairs`, rest lengths of their offset) without changing the body."""
    body = msd.Body.grid(shape, spacing=0.5, stiffness=7.0, neighbours=(1, 2, 4), damping=0.2)
    lattice = body.spring_set
    assert is_lattice(body)
    offsets = neighbour_offsets(len(shape), (1, 2, 4))
    for values, value in ((lattice.stiffness, 7.0), (lattice.damping, 0.2)):
        assert values.shape == (len(offsets),) and np.all(values == value)
    assert not lattice.stiffness.flags.writeable  # changed through set_springs only
    version, pairs = body.version, grid_pairs(shape, offsets)
    edges = body.edges()
    assert isinstance(edges, EdgeSprings) and body.n_springs == edges.count == len(pairs)
    assert np.array_equal(edges.a, pairs[:, 0]) and np.array_equal(edges.b, pairs[:, 1])
    kinds = np.repeat(np.arange(len(offsets)), lattice.counts)
    assert np.array_equal(edges.rest_lengths, 0.5 * np.sqrt((offsets**2).sum(axis=1))[kinds])
    assert np.all(edges.stiffness == 7.0) and np.all(edges.damping == 0.2)
    assert body.spring_set is lattice and body.version == version  # nothing changed
    assert body.edges() is not edges  # laid out anew: the body keeps no copy


def test_one_spring_of_a_lattice_reads_as_laid_out() -> None:
    """`springs[k]` of a lattice (found from the counts) is spring k of the edge list."""
    body = jelly((3, 4, 5), 0.2)
    edges = body.edges()
    for index in range(body.n_springs):
        assert body.spring_set.spring(index) == edges.spring(index)
    spring = body.springs[77]
    assert (spring.a, spring.b) == (edges.a[77], edges.b[77])
    assert spring.rest_length == edges.rest_lengths[77] and spring.damping == 0.2


def test_the_lattice_gives_the_forces_of_its_springs(kernel: str) -> None:
    """Forces, energy and dashpot power of a lattice are those of its springs laid out, in
    2-D and 3-D, with and without dashpots."""
    for body in (jelly((5, 4, 6)), jelly((5, 4, 6), 0.4), jelly((9, 7), 0.4)):
        twin = laid_out(body)
        x, v = body.positions, body.velocities
        springs = make_kernel(kernel)
        forces = np.zeros_like(x)
        stretch, power = springs.spring_forces(Layout(body), x, v, forces, None)
        energy = springs.elastic_energy(Layout(body), x, None)
        reference = NumpyKernel()
        expected = np.zeros_like(x)
        assert (stretch, power) == pytest.approx(
            reference.spring_forces(Layout(twin), x, v, expected), rel=1e-12
        )
        np.testing.assert_allclose(forces, expected, rtol=1e-12, atol=1e-12)
        assert energy == pytest.approx(reference.elastic_energy(Layout(twin), x), rel=1e-12)


@pytest.mark.parametrize("threads", [False, True])
def test_a_run_matches_the_laid_out_body(
    kernel: str, threads: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same steps, and the same ledger, on the lattice or its edge list (bit for bit on
    the numpy kernel, which lays the lattice out itself; to rounding on the gather)."""
    if threads and kernel == "numpy":
        pytest.skip("threads are the numba kernel's")
    if threads:
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_SPRINGS", 0)
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_GATHERED", 0)
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_PARTICLES", 0)
    trajectories = []
    for body in (jelly((6, 5, 7), 0.3), laid_out(jelly((6, 5, 7), 0.3))):
        body.positions[:, 1] += 0.05
        forces = [msd.Gravity((0, -9.81, 0)), msd.Ground()]
        sim = msd.Simulation(body, msd.Verlet(0.01), dt=1e-3, forces=forces)
        trajectories.append(sim.run(steps=40, record_velocities=True))
    assert is_lattice(body) is False
    kept, arrays = trajectories
    tolerance = {"rtol": 0.0, "atol": 0.0} if kernel == "numpy" else {"rtol": 1e-10, "atol": 1e-12}
    np.testing.assert_allclose(kept.positions, arrays.positions, **tolerance)
    np.testing.assert_allclose(kept.velocities, arrays.velocities, **tolerance)
    np.testing.assert_allclose(kept.energies.total, arrays.energies.total, rtol=1e-12)
    np.testing.assert_allclose(kept.energies.elastic, arrays.energies.elastic, rtol=1e-12)
    for name in ("dashpot", "integrator", "ground"):
        dissipated = kept.energies.dissipated[name], arrays.energies.dissipated[name]
        np.testing.assert_allclose(*dissipated, rtol=1e-10, atol=1e-15)


def test_edits_of_a_lattice_are_for_all_its_springs_and_count(kernel: str) -> None:
    """A lattice takes one new value for all its springs; an edit of some springs asks for
    `springs_as_edges` first, which keeps the springs and counts; every edit counts
    (`Body.version`) and changes the forces at once."""
    body = jelly((4, 4, 4))
    version = body.version
    body.set_springs(stiffness=400.0)
    assert is_lattice(body) and body.version == version + 1
    assert np.all(body.spring_set.stiffness == 400.0)
    sim = msd.Simulation(body, msd.SymplecticEuler(), dt=1e-4)
    sim.step()
    for edit in (
        lambda: body.set_springs([5], stiffness=900.0),
        lambda: body.set_springs(stiffness=np.full(body.n_springs, 900.0)),
        lambda: body.add_springs([[0, 5]]),
        lambda: setattr(body.springs[5], "stiffness", 900.0),
    ):
        with pytest.raises(ValueError, match=r"body\.springs_as_edges\(\)"):
            edit()
    version = body.version
    edges = body.springs_as_edges()
    assert body.spring_set is edges and body.version == version + 1
    assert body.springs_as_edges() is edges and body.version == version + 1  # once
    body.springs[5].stiffness = 900.0
    assert edges.stiffness[5] == 900.0 and edges.stiffness[4] == 400.0
    x, v = body.positions, body.velocities
    forces, expected = np.zeros_like(x), np.zeros_like(x)
    sim.dynamics.springs.spring_forces(Layout(body), x, v, forces, None)
    NumpyKernel().spring_forces(Layout(body), x, v, expected)
    np.testing.assert_allclose(forces, expected, rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match="damping"):
        body.set_springs(damping=-1.0)


def test_copy_pickle_and_growth_keep_the_springs() -> None:
    body = jelly((3, 4, 5), 0.1)
    for twin in (body.copy(), pickle.loads(pickle.dumps(body))):
        assert is_lattice(twin) and twin.n_springs == body.n_springs
        assert np.array_equal(twin.edges().b, body.edges().b)
    twin = body.copy()
    twin.set_springs(stiffness=5.0)
    assert np.all(body.spring_set.stiffness == 300.0)  # the copy's values are its own
    grown = body.copy()
    grown.add_particles([[5.0, 5.0, 5.0]])  # a particle outside the grid, without springs
    assert grown.n_springs == body.n_springs and is_lattice(grown)
    grown.springs_as_edges()
    grown.add_springs([[0, len(grown) - 1]], stiffness=2.0)
    assert grown.n_springs == body.n_springs + 1 and grown.edges().stiffness[-1] == 2.0
    assert np.array_equal(grown.edges().a[:-1], body.edges().a)


def test_a_grid_without_springs_takes_an_edge_list() -> None:
    """`Body.grid(..., neighbours=())` places particles only: springs added to it make its
    spring set an edge list (as a student's own grid_springs would)."""
    body = msd.Body.grid((3, 3, 3), spacing=0.5, neighbours=())
    assert body.n_springs == 0
    body.add_springs([[0, 1], [1, 2]], stiffness=2.0)
    assert isinstance(body.spring_set, EdgeSprings) and body.n_springs == 2
    np.testing.assert_allclose(body.edges().rest_lengths, 0.5)


@pytest.mark.parametrize("kernel", ["numpy", "numba"])
def test_a_new_spring_set_counts_as_an_edit(kernel):
    """Assigning ``body.spring_set`` adds one to the version, so what was kept for the old
    springs (a kernel's edge list, the incidence lists) is made again."""
    body = msd.Body.grid((3, 3), spacing=1.0, stiffness=10.0)
    sim = msd.Simulation(body, msd.SymplecticEuler(), dt=1e-3, kernel=kernel)
    sim.step()
    assert len(body.springs_touching(np.array([4]))) == 4
    version = body.version
    body.spring_set = EdgeSprings.empty()
    assert body.version == version + 1
    assert len(body.springs_touching(np.array([4]))) == 0
    body.positions = body.positions + 0.1 * np.eye(2)[np.arange(9) % 2]  # stretched, no springs
    sim.step()
    np.testing.assert_array_equal(body.velocities, 0.0)
