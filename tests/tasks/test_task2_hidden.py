"""Instructor-only checks of task 2 (left out of the student release)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_task2 import named

from msdlab.course import oracles
from msdlab.course.feedback import (
    as_array,
    expect,
    expect_nontrivial,
    grid_place,
    percent,
    returned,
    vec,
)

import reference_hidden as reference

pytestmark = [pytest.mark.task2, pytest.mark.hidden]


@pytest.mark.points(3)
@settings(max_examples=25)
@given(
    shape=st.tuples(st.integers(1, 5), st.integers(1, 5), st.integers(1, 5)),
    spacing=st.floats(0.05, 3.0),
    stiffness=st.floats(0.01, 10.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_any_grid_size_spacing_and_stiffness(task2, shape, spacing, stiffness, seed):
    """Eq. (1.1)-(1.2) hold for every grid shape (1 to 5 per axis), spacing and stiffness."""
    rng = np.random.default_rng(seed)
    x = oracles.template_positions(shape, spacing, (0.3, 1.0, -0.2))
    x = x + 0.2 * spacing * rng.standard_normal(x.shape)
    got = as_array(task2.spring_acceleration(x.copy(), spacing, stiffness), "spring_acceleration")
    expected = reference.pair_acceleration(
        x.reshape(-1, 3), reference.axis_pairs(shape), spacing, stiffness
    ).reshape(x.shape)
    expect(got.shape == x.shape, saw=f"a {shape} grid gave accelerations of shape {got.shape}")
    error = np.linalg.norm(got - expected, axis=-1)
    worst = np.unravel_index(np.argmax(error), shape)
    scale = max(float(np.max(np.linalg.norm(expected, axis=-1))), stiffness * spacing * 1e-3)
    expect(
        error[worst] <= 1e-9 * scale,
        saw=f"on a deformed {shape} grid (spacing {spacing:.3g}, k = {stiffness:.3g}) the "
        f"{grid_place(worst, shape)} gets {vec(got[worst])} instead of {vec(expected[worst])}",
        cause=named(task2, got, x, spacing, stiffness)
        or "a kernel written for one grid size or spacing (hard-coded N, 2/N or indices)",
    )


@pytest.mark.points(2)
def test_one_displaced_corner(task2):
    """Moving one corner particle loads exactly its 3 springs, each once."""
    shape, h, k = (3, 4, 5), 1.0, 2.0
    x = oracles.template_positions(shape, h, (0.0, 0.0, 0.0))
    x[0, 0, 0] += (-0.2, -0.1, -0.3)  # away from all three neighbours
    got = as_array(task2.spring_acceleration(x.copy(), h, k), "spring_acceleration", x.shape)
    expected = reference.pair_acceleration(
        x.reshape(-1, 3), reference.axis_pairs(shape), h, k
    ).reshape(x.shape)
    touched = np.linalg.norm(expected, axis=-1) > 0
    ratio = np.linalg.norm(got[0, 0, 0]) / np.linalg.norm(expected[0, 0, 0])
    expect(
        np.allclose(got, expected, rtol=1e-9, atol=1e-12),
        saw=f"with only the corner (0, 0, 0) moved, it gets {vec(got[0, 0, 0])} (expected "
        f"{vec(expected[0, 0, 0])}, {ratio:.3g}× that) and {int(np.sum(np.any(got != 0, -1)))} "
        f"particles feel a force (expected {int(touched.sum())}: the corner and its 3 "
        "neighbours)",
        cause=named(task2, got, x, h, k)
        or "border neighbours missing, duplicated, or wrapped around to the opposite face",
    )


@pytest.mark.points(1)
def test_coincident_neighbours_give_no_nan(task2):
    """Two neighbours at the same point: that spring adds nothing, no NaN appears."""
    x = oracles.template_positions((2, 2, 2), 0.5, (0.0, 0.0, 0.0))
    x[1, 0, 0] = x[0, 0, 0]
    got = np.asarray(
        returned(task2.spring_acceleration(x.copy(), 0.5, 1.0), "spring_acceleration"), float
    )
    expect(
        np.all(np.isfinite(got)),
        saw="two axis neighbours at the same position made the accelerations NaN or infinite",
        cause="dividing by the spring length without a guard for zero length",
    )
    expected = reference.pair_acceleration(
        x.reshape(-1, 3), reference.axis_pairs((2, 2, 2)), 0.5, 1.0
    ).reshape(x.shape)
    expect(
        np.allclose(got, expected, atol=1e-12),
        saw=f"with a zero-length spring the other springs' forces are wrong (largest error "
        f"{percent(np.max(np.abs(got - expected)) / np.max(np.abs(expected)))})",
        cause=named(task2, got, x, 0.5, 1.0)
        or "a zero-length spring should add nothing; the other springs act as usual",
    )


@pytest.mark.points(1)
def test_positions_are_not_modified(task2):
    """spring_acceleration leaves the positions it is given unchanged."""
    rng = np.random.default_rng(8)
    x = oracles.template_positions((3, 3, 2), 0.1, (0.0, 0.0, 0.0))
    x += 0.01 * rng.standard_normal(x.shape)
    kept = x.copy()
    got = as_array(task2.spring_acceleration(x, 0.1, 0.5), "spring_acceleration", x.shape)
    expect_nontrivial(got, kept, "spring_acceleration of a deformed grid")
    expect(
        np.array_equal(x, kept),
        saw="spring_acceleration changed the positions array it was given",
        cause="in-place operations on x (x -= ..., x[...] = ...): the caller's state is corrupted",
    )
