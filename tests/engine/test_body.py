"""Body, Particle and Spring: the public API, array views and grids."""

import math

import numpy as np
import pytest

import msdlab as msd


def two_particles() -> msd.Body:
    body = msd.Body()
    a = body.add_particle(msd.Particle(position=(0, 0, 0), mass=1.0, fixed=True))
    b = body.add_particle(msd.Particle(position=(1, 0, 0), velocity=(0, 0, 0), mass=2.0))
    body.add_spring(msd.Spring(a, b, stiffness=10.0, rest_length=None, damping=0.0))
    return body


def test_issue_example_builds_a_body_with_array_views():
    body = two_particles()
    assert body.dim == 3 and len(body) == 2 and body.n_springs == 1
    assert body.positions.shape == (2, 3) and body.velocities.shape == (2, 3)
    np.testing.assert_array_equal(body.masses, [1.0, 2.0])
    np.testing.assert_array_equal(body.fixed, [True, False])
    assert body.edges().rest_lengths[0] == 1.0  # None took the current distance


def test_particle_and_spring_objects_read_and_write_the_arrays():
    body = two_particles()
    particle = body.particles[1]
    particle.position = (2, 0, 0)
    assert body.positions[1, 0] == 2.0
    body.velocities[1] = (0, 3, 0)
    assert particle.velocity[1] == 3.0
    spring = body.springs[0]
    spring.stiffness = 20.0
    assert body.edges().stiffness[0] == 20.0
    assert spring.length() == pytest.approx(2.0)
    assert spring.energy() == pytest.approx(0.5 * 20.0 * 1.0**2)


def test_added_particle_object_becomes_a_view_of_the_body():
    body = msd.Body()
    particle = msd.Particle(position=(0, 1))
    index = body.add_particle(particle)
    body.positions[index] = (5, 6)
    np.testing.assert_array_equal(particle.position, [5, 6])
    assert particle.index == 0 and body.dim == 2


def test_fixing_a_particle_zeroes_its_velocity():
    body = msd.Body()
    body.add_particle(msd.Particle(position=(0, 0), velocity=(1, 1)))
    body.particles[0].fixed = True
    np.testing.assert_array_equal(body.velocities[0], [0, 0])


def test_views_survive_many_additions_and_copy_is_independent():
    body = msd.Body()
    for i in range(100):
        body.add_particle(msd.Particle(position=(i, 0)))
    body.add_springs([[i, i + 1] for i in range(99)], stiffness=2.0)
    assert body.n_springs == 99 and np.all(body.edges().rest_lengths == 1.0)
    copy = body.copy()
    copy.positions[0] = (-5, -5)
    assert body.positions[0, 0] == 0.0


@pytest.mark.parametrize("shape", [(4, 5), (3, 4, 5)])
def test_grid_springs_counts_and_rest_lengths(shape):
    n_axis = sum(math.prod(shape) // n * (n - 1) for n in shape)
    body = msd.Body.grid(shape, spacing=0.5, neighbours=(1,))
    assert body.n_springs == n_axis
    np.testing.assert_allclose(body.edges().rest_lengths, 0.5)
    full = msd.Body.grid(shape, spacing=0.5, neighbours=(1, 2, 3))
    lengths = np.linalg.norm(
        full.positions[full.edges().a] - full.positions[full.edges().b], axis=1
    )
    np.testing.assert_allclose(full.edges().rest_lengths, lengths)  # at rest: no pre-stress
    assert set(np.round(full.edges().rest_lengths / 0.5, 6)) <= {
        1.0,
        round(2**0.5, 6),
        round(3**0.5, 6),
    }


def test_cubic_grid_has_26_neighbours_inside_and_known_spring_count():
    n = 4
    body = msd.Body.grid((n, n, n), neighbours=(1, 2, 3))
    expected = 3 * n * n * (n - 1) + 6 * n * (n - 1) ** 2 + 4 * (n - 1) ** 3
    assert body.n_springs == expected
    degree = np.bincount(np.concatenate([body.edges().a, body.edges().b]), minlength=len(body))
    inner = np.ravel_multi_index((1, 2, 1), (n, n, n))
    assert degree[inner] == 26 and degree[0] == 7
    pairs = {tuple(sorted(p)) for p in zip(body.edges().a, body.edges().b)}
    assert len(pairs) == body.n_springs  # no spring made twice


def test_grid_layout_matches_coordinates():
    body = msd.Body.grid((3, 4, 2), spacing=0.1, origin=(-1, 1.5, -1))
    grid = body.positions.reshape(3, 4, 2, 3)
    np.testing.assert_allclose(grid[2, 3, 1], (-1 + 0.2, 1.5 + 0.3, -1 + 0.1))


def test_rotation_matrix_is_right_handed():
    rotation = msd.rotation_matrix(90, axis=(0, 0, 1))
    np.testing.assert_allclose(rotation @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(msd.rotation_matrix(90) @ [1, 0], [0, 1], atol=1e-15)


def test_rotate_keeps_shape_and_centre():
    body = msd.Body.grid((3, 3, 3), spacing=0.2, neighbours=(1, 2))
    centre = body.center_of_mass()
    body.rotate(msd.rotation_matrix(37, axis=(1, 2, 3)))
    np.testing.assert_allclose(body.center_of_mass(), centre, atol=1e-14)
    lengths = np.linalg.norm(
        body.positions[body.edges().a] - body.positions[body.edges().b], axis=1
    )
    np.testing.assert_allclose(lengths, body.edges().rest_lengths)


def test_store_state_takes_the_arrays_uncopied():
    body = msd.Body.grid((3, 2), spacing=0.5)
    body.add_particles([(9.0, 9.0)])  # room to spare in the particle buffers
    before = body.positions
    x_new, v_new = np.full_like(before, 1.0), np.full_like(before, 2.0)
    body.store_state(x_new, v_new)
    assert body.positions is x_new and body.velocities is v_new  # not copied
    assert before[0, 0] == 0.0  # an array read before keeps the old state
    body.add_particles([(5.0, 6.0)], masses=2.0)  # the buffers grow again from the state
    np.testing.assert_array_equal(body.positions[:-1], 1.0)
    np.testing.assert_array_equal(body.positions[-1], (5.0, 6.0))
    np.testing.assert_array_equal(body.masses[-2:], (1.0, 2.0))


def test_store_state_refuses_arrays_of_another_shape():
    body = msd.Body.grid((2, 2))
    x_new, v_new = np.ones((4, 2)), np.zeros((4, 2))
    body.add_particles([(5.0, 6.0)])
    with pytest.raises(ValueError, match="5 particles in 2-D"):
        body.store_state(x_new, v_new)


@pytest.mark.parametrize("particles", [[7], [0, 7], [3, 8, 40]])
def test_springs_touching_are_the_springs_with_an_end_among_the_particles(particles) -> None:
    body = msd.Body.grid((6, 9), neighbours=(1, 2))
    wanted = np.isin(body.edges().a, particles) | np.isin(body.edges().b, particles)
    touching = body.springs_touching(np.array(particles))
    np.testing.assert_array_equal(touching, np.flatnonzero(wanted))
