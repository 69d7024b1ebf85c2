"""Internal forces: Newton's third law, rotation and translation invariance, dashpots."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import msdlab as msd
from msdlab.engine.backends import numpy as numpy_backend
from msdlab.engine.backends.layout import Layout

coordinates = st.floats(-3.0, 3.0, allow_nan=False, allow_infinity=False)


@st.composite
def random_bodies(draw: st.DrawFn) -> msd.Body:
    """A few particles in 2-D or 3-D with random springs, rest lengths and dashpots."""
    dim = draw(st.sampled_from([2, 3]))
    count = draw(st.integers(2, 7))
    x = draw(arrays(float, (count, dim), elements=coordinates))
    v = draw(arrays(float, (count, dim), elements=coordinates))
    x += np.arange(count)[:, None] * 0.37  # keep particles apart
    pairs = [(i, j) for i in range(count) for j in range(i + 1, count)]
    chosen = draw(st.lists(st.sampled_from(pairs), min_size=1, max_size=len(pairs), unique=True))
    stiffness = draw(arrays(float, len(chosen), elements=st.floats(0.0, 50.0)))
    rest = draw(arrays(float, len(chosen), elements=st.floats(0.1, 3.0)))
    damping = draw(arrays(float, len(chosen), elements=st.floats(0.0, 5.0)))
    return msd.Body.from_arrays(
        x, chosen, velocities=v, stiffness=stiffness, rest_lengths=rest, damping=damping
    )


@st.composite
def rotations(draw: st.DrawFn, dim: int) -> np.ndarray:
    angle = draw(st.floats(-180.0, 180.0))
    if dim == 2:
        return msd.rotation_matrix(angle)
    axis = draw(
        arrays(float, 3, elements=st.floats(-1, 1)).filter(lambda a: np.linalg.norm(a) > 0.1)
    )
    return msd.rotation_matrix(angle, axis)


def forces(body: msd.Body, x: np.ndarray | None = None, v: np.ndarray | None = None) -> np.ndarray:
    x = body.positions if x is None else x
    v = body.velocities if v is None else v
    return numpy_backend.spring_forces(body, x, v)[0]


def dashpot_power(body: msd.Body) -> float:
    """The power (W) the dashpots take, from the numpy kernel's pass over the springs."""
    x = body.positions
    return (
        numpy_backend.NumpyKernel()
        .spring_forces(Layout(body), x, body.velocities, np.zeros_like(x))
        .power
    )


@given(random_bodies())
def test_internal_forces_sum_to_zero(body):
    total = forces(body).sum(axis=0)
    scale = np.abs(forces(body)).sum() + 1.0
    assert np.all(np.abs(total) <= 1e-12 * scale)


@given(random_bodies(), st.data())
def test_forces_rotate_with_the_body(body, data):
    rotation = data.draw(rotations(body.dim))
    rotated = forces(body, body.positions @ rotation.T, body.velocities @ rotation.T)
    np.testing.assert_allclose(rotated, forces(body) @ rotation.T, atol=1e-10)


@given(random_bodies(), arrays(float, 3, elements=coordinates))
def test_forces_ignore_translation_and_uniform_velocity(body, shift):
    shift = shift[: body.dim]
    moved = forces(body, body.positions + 10 * shift, body.velocities + shift)
    np.testing.assert_allclose(moved, forces(body), atol=1e-9)


@given(random_bodies())
def test_vectorised_forces_equal_the_readable_spring_class(body):
    readable = np.zeros_like(body.positions)
    for spring in body.springs:
        f = spring.force()
        readable[spring.a] += f
        readable[spring.b] -= f
    np.testing.assert_allclose(forces(body), readable, rtol=1e-12, atol=1e-12)
    energy = sum(spring.energy() for spring in body.springs)
    np.testing.assert_allclose(msd.elastic_energy(body), energy, rtol=1e-12, atol=1e-300)


def test_stretched_spring_pulls_the_ends_together():
    body = msd.Body.from_arrays(
        [[0.0, 0.0], [2.0, 0.0]], [[0, 1]], stiffness=3.0, rest_lengths=[1.0]
    )
    f = forces(body)
    np.testing.assert_allclose(f, [[3.0, 0.0], [-3.0, 0.0]])  # eq. (1.2): k (l - |d|) d/|d|


def test_dashpot_does_not_damp_rigid_rotation():
    body = msd.Body.grid((3, 3), spacing=1.0, neighbours=(1, 2), damping=5.0)
    centre = body.center_of_mass()
    r = body.positions - centre
    body.velocities = np.c_[-r[:, 1], r[:, 0]] * 2.0  # rigid rotation, ω = 2 rad/s
    np.testing.assert_allclose(forces(body), 0.0, atol=1e-12)
    assert dashpot_power(body) < 1e-20


def test_dashpot_damps_stretching():
    body = msd.Body.from_arrays(
        [[0.0, 0.0], [1.0, 0.0]], [[0, 1]], velocities=[[-1.0, 0], [1.0, 0]], damping=2.0
    )
    f = forces(body)
    np.testing.assert_allclose(f, [[4.0, 0.0], [-4.0, 0.0]])  # -c (v_a - v_b)·n n
    assert dashpot_power(body) == 8.0


def test_coincident_particles_give_no_force_and_no_nan():
    body = msd.Body.from_arrays([[0.0, 0.0], [1.0, 0.0]], [[0, 1]])
    body.positions = [[0.5, 0.0], [0.5, 0.0]]
    assert np.all(forces(body) == 0.0)
