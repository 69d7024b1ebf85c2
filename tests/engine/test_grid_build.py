"""Body.grid: spring counts, rest lengths and pairs of the lattice neighbours."""

from __future__ import annotations

import math

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.model.lattice import grid_pairs, neighbour_offsets


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8])
def test_cube_with_three_neighbour_shells(n: int) -> None:
    body = msd.Body.grid((n, n, n), spacing=0.25, stiffness=3.0, neighbours=(1, 2, 3), damping=0.1)
    axis, face, diagonal = 3 * n * n * (n - 1), 6 * n * (n - 1) ** 2, 4 * (n - 1) ** 3
    assert len(body) == n**3
    assert body.n_springs == axis + face + diagonal
    rest = np.sort(body.edges().rest_lengths)
    np.testing.assert_allclose(rest[:axis], 0.25, rtol=1e-15)
    np.testing.assert_allclose(rest[axis : axis + face], 0.25 * math.sqrt(2), rtol=1e-15)
    np.testing.assert_allclose(rest[axis + face :], 0.25 * math.sqrt(3), rtol=1e-15)
    lengths = np.linalg.norm(
        body.positions[body.edges().a] - body.positions[body.edges().b], axis=1
    )
    np.testing.assert_allclose(lengths, body.edges().rest_lengths, rtol=1e-12)  # built at rest
    assert np.all(body.edges().stiffness == 3.0) and np.all(body.edges().damping == 0.1)
    assert msd.elastic_energy(body) == pytest.approx(0.0, abs=1e-25)


def test_every_neighbour_pair_once() -> None:
    shape = (4, 3, 5)
    body = msd.Body.grid(shape, neighbours=(1, 2, 3))
    coords = np.array(np.unravel_index(np.arange(len(body)), shape)).T
    expected = {
        (p, q)
        for p in range(len(body))
        for q in range(p + 1, len(body))
        if 1 <= np.sum((coords[p] - coords[q]) ** 2) <= 3
    }
    pairs = {tuple(sorted(pair)) for pair in zip(body.edges().a.tolist(), body.edges().b.tolist())}
    assert pairs == expected and body.n_springs == len(expected)


def test_square_grid_and_pair_blocks() -> None:
    nx, ny = 6, 4
    body = msd.Body.grid((nx, ny), spacing=0.5, neighbours=(1, 2, 4))
    axis = nx * (ny - 1) + ny * (nx - 1)
    diagonals = 2 * (nx - 1) * (ny - 1)
    bending = nx * (ny - 2) + ny * (nx - 2)
    assert body.n_springs == axis + diagonals + bending
    offsets = neighbour_offsets(2, (1, 2, 4))
    pairs = grid_pairs((nx, ny), offsets)
    assert body.spring_set.counts.sum() == len(pairs) == body.n_springs
    kinds = np.repeat(np.arange(len(offsets)), body.spring_set.counts)
    np.testing.assert_array_equal(np.stack([body.edges().a, body.edges().b], 1), pairs)
    rest = 0.5 * np.sqrt((offsets**2).sum(axis=1))[kinds]
    np.testing.assert_allclose(body.edges().rest_lengths, rest, rtol=1e-15)


def test_grid_arguments_are_checked() -> None:
    with pytest.raises(ValueError, match="mass"):
        msd.Body.grid((3, 3), mass=0.0)
    with pytest.raises(ValueError, match="stiffness"):
        msd.Body.grid((3, 3), stiffness=-1.0)
    with pytest.raises(ValueError, match="neighbours"):
        msd.Body.grid((3, 3), neighbours=(0,))
