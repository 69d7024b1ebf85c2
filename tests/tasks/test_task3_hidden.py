"""Instructor-only checks of task 3 (left out of the student release)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_task3 import matrix_mistake, named, rotation_at_fault

import msdlab as msd
from msdlab.course.experiments import cube_ratio
from msdlab.course.feedback import as_array, expect, num, relative_error, returned

import reference_hidden as reference

pytestmark = [pytest.mark.task3, pytest.mark.hidden]

# The cube experiment is deterministic: rounding (another order of sums, another way to
# rotate) moves its flatness ratio by less than 1e-9, while a spacing 5 % off moves it
# by 1e-4 to 1e-2 (measured), so "the experiment as described" is compared this closely.
SAME_EXPERIMENT = 1e-6

axes = st.tuples(*3 * [st.floats(-2.0, 2.0)]).filter(lambda a: np.linalg.norm(a) > 0.1)
angles = st.floats(-360.0, 360.0)


@pytest.mark.points(2)
@settings(max_examples=30)
@given(axis=axes, first=angles, second=angles)
def test_rotations_compose_and_invert(task3, axis, first, second):
    """About one axis, turns add up, a turn back is the transpose, and the axis length is free."""
    r1 = as_array(task3.rotation_matrix(first, axis), "rotation_matrix", (3, 3))
    r2 = as_array(task3.rotation_matrix(second, axis), "rotation_matrix", (3, 3))
    both = as_array(task3.rotation_matrix(first + second, axis), "rotation_matrix", (3, 3))
    back = as_array(task3.rotation_matrix(-first, axis), "rotation_matrix", (3, 3))
    longer = as_array(
        task3.rotation_matrix(first, tuple(3.0 * np.asarray(axis))), "rotation_matrix", (3, 3)
    )
    expect(
        np.allclose(r2 @ r1, both, atol=1e-9) and np.allclose(back, r1.T, atol=1e-9),
        saw=f"about {axis}: R({num(second)}°)·R({num(first)}°) differs from R(sum) by "
        f"{num(np.max(np.abs(r2 @ r1 - both)))}, or R(-θ) from R(θ)ᵀ",
        cause=matrix_mistake(task3) or "a matrix that is not a rotation about the given axis",
    )
    expect(
        np.allclose(longer, r1, atol=1e-9),
        saw="scaling the axis by 3 changed the rotation",
        cause=matrix_mistake(task3) or "the axis is not normalised before use",
    )
    expect(
        np.allclose(r1, msd.rotation_matrix(first, axis), atol=1e-9),
        saw=f"rotation_matrix({num(first)}, {axis}) is not the turn by {num(first)}° about {axis}",
        cause=matrix_mistake(task3)
        or "radians where degrees are given, or a term of Rodrigues' formula missing",
    )


@pytest.mark.points(2)
@settings(max_examples=20)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 12), e=st.integers(1, 40))
def test_any_spring_list(task3, seed, n, e):
    """Random spring graphs (many springs on one particle, any order) obey eq. (1.1)-(1.2)."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-1.0, 1.0, (n, 3))
    i = rng.integers(0, n, e)
    j = (i + rng.integers(1, n, e)) % n
    springs = np.stack([i, j], axis=1)
    rest = rng.uniform(0.2, 1.5, e)
    kept = (x.copy(), springs.copy(), rest.copy())
    got = as_array(task3.spring_acceleration(x, springs, rest, 0.7), "spring_acceleration")
    expected = reference.pair_acceleration(x, springs, rest, 0.7)
    expect(
        got.shape == x.shape and relative_error(got, expected) < 1e-9,
        saw=f"for {e} random springs between {n} particles the accelerations are off by "
        f"{num(relative_error(got, expected) if got.shape == x.shape else np.inf)} (relative)",
        cause=(named(task3, got, x, springs, rest, 0.7) if got.shape == x.shape else None)
        or "a particle with several springs must get the sum of all of them (np.add.at, "
        "np.bincount or a loop; a[i] += f keeps only one of repeated indices)",
    )
    expect(
        all(np.array_equal(a, b) for a, b in zip((x, springs, rest), kept)),
        saw="spring_acceleration changed its inputs",
        cause="in-place operations on the positions, springs or rest lengths",
    )


@pytest.mark.points(1)
def test_zero_length_spring_gives_no_nan(task3):
    """A spring whose ends coincide adds nothing: no NaN."""
    x = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    springs = np.array([[0, 1], [1, 2]])
    got = task3.spring_acceleration(x, springs, np.array([0.5, 0.5]), 1.0)
    got = np.asarray(returned(got, "spring_acceleration"), float)
    expected = reference.pair_acceleration(x, springs, np.array([0.5, 0.5]), 1.0)
    expect(
        np.all(np.isfinite(got)),
        saw=f"with a zero-length spring the accelerations are {got.tolist()}",
        cause="dividing by the spring length without a guard for zero length",
    )
    expect(
        np.allclose(got, expected, atol=1e-12),
        saw=f"with a zero-length spring beside a stretched one the accelerations are "
        f"{got.tolist()}, eq. (1.1)-(1.2) give {expected.tolist()}",
        cause=named(task3, got, x, springs, np.array([0.5, 0.5]), 1.0)
        or "the zero-length spring should add nothing and the other one act as usual; "
        "see the checks of the spring sum for what is wrong there",
    )


@pytest.mark.points(1)
def test_cube_tilted_about_x_collapses(task3):
    """Axis springs only, tilted 30° about x: the cube folds flat too; in every setting (the
    public check's included) the ratio is the one of the experiment as described."""
    got = cube_ratio(task3, 30.0, (1.0, 0.0, 0.0), (1,))
    expected = reference.drop_rotated_cube(30.0, (1.0, 0.0, 0.0), (1,))
    expect(
        abs(got - expected) < 0.1 and got < 0.3,
        saw=f"tilted 30° about x the flatness ratio is {num(got)}; the experiment gives "
        f"{num(expected)} (a collapse)",
        cause=lambda: (
            rotation_at_fault(task3) or "a rotation about the wrong axis, or a different experiment"
        ),
    )
    for axis, angle in (((0.0, 0.0, 1.0), 45.0), ((0.0, 1.0, 0.0), 45.0)):
        got = cube_ratio(task3, angle, axis, (1,))
        expected = reference.drop_rotated_cube(angle, axis, (1,))
        expect(
            abs(got - expected) <= SAME_EXPERIMENT,
            saw=f"drop_rotated_cube({angle}, {axis}) = {num(got, 8)}, but the experiment as "
            f"described gives a flatness ratio of {num(expected, 8)}",
            cause=lambda: (
                rotation_at_fault(task3)
                or "a different experiment: check the rotation, the lift to y = LIFT, the "
                "number of steps, dt, gravity and the floor"
            ),
        )


@pytest.mark.points(1)
def test_drop_rotated_cube_uses_steps_and_neighbours(task3):
    """One step leaves the cube as it was; with 1, √2, √3 springs the tilted cube stands."""
    still = cube_ratio(task3, 45.0, (0.0, 0.0, 1.0), (1,), steps=1)
    expect(
        abs(still - 1.0) < 0.01,
        saw=f"drop_rotated_cube(..., steps=1) = {num(still)}: in a single step the cube "
        "cannot change its shape that much",
        cause=lambda: (
            rotation_at_fault(task3)
            or "the number of steps is ignored (run `steps` steps, not a fixed number)"
        ),
    )
    held = cube_ratio(task3, 45.0, (0.0, 0.0, 1.0), (1, 2, 3))
    expected = reference.drop_rotated_cube(45.0, (0.0, 0.0, 1.0), (1, 2, 3))
    expect(
        abs(held - expected) < 0.1,
        saw=f"with springs to neighbours (1, 2, 3) the tilted cube's flatness ratio is "
        f"{num(held)}, the experiment gives {num(expected)} (it stands)",
        cause=lambda: (
            rotation_at_fault(task3)
            or "the neighbours argument is ignored: pass it to msd.Body.grid"
        ),
    )
