"""Checks of task 3: rotating the layout, orientation-free spring forces, the collapse."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import msdlab as msd
from msdlab.course import oracles
from msdlab.course.experiments import cube_ratio
from msdlab.course.feedback import (
    as_array,
    expect,
    expect_nontrivial,
    matching_variant,
    num,
    percent,
    relative_error,
    vec,
)

pytestmark = pytest.mark.task3

AXES = ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 2.0, 0.0), (1.0, -2.0, 0.5))


def jelly(shape=(3, 4, 2), neighbours=(1, 2, 3), spacing=0.5, stiffness=0.5):
    return oracles.grid_body(shape, spacing, stiffness, neighbours, origin=(-0.5, 1.0, 0.3))


def springs_of(body):
    edges = body.edges()
    return np.stack([edges.a, edges.b], axis=1), edges.rest_lengths.copy()


DEGREES_AS_RADIANS = (
    "radians where degrees are given: the angle is in degrees, θ = np.radians(angle_degrees)"
)
LEFT_HANDED = "a left-handed turn (the transpose): flip the sign of the sin terms"


def matrix_mistakes(angle, axis):
    """Matrices (3, 3) that typical mistakes in rotation_matrix(angle, axis) give, by cause."""
    expected = msd.rotation_matrix(angle, axis)
    theta, n = np.radians(angle), np.asarray(axis, dtype=float)
    unit = n / np.linalg.norm(n)
    return {
        LEFT_HANDED: expected.T,
        DEGREES_AS_RADIANS: msd.rotation_matrix(np.degrees(angle), axis),
        "the axis is not normalised: divide it by its length first": (
            np.cos(theta) * np.eye(3)
            + np.sin(theta) * np.cross(np.eye(3), n)
            + (1 - np.cos(theta)) * np.outer(n, n)
        ),
        "Rodrigues' formula with the unit axis n lacks its (1 - cos θ) n nᵀ term": (
            np.cos(theta) * np.eye(3) + np.sin(theta) * np.cross(np.eye(3), unit)
        ),
    }


@functools.lru_cache(maxsize=16)  # per task module: the checks of one submission ask often
def matrix_mistake(task3):
    """The typical mistake the student's rotation_matrix is recognised as (a turn by 30° about
    the axis (1, -2, 0.5): every mistake gives another matrix), or None.

    The checks of rotation_matrix, and of rotate_layout and drop_rotated_cube (which use it),
    name it as their cause, so the report names the one mistake once.
    """
    axis, angle = (1.0, -2.0, 0.5), 30.0
    try:
        got = np.asarray(task3.rotation_matrix(angle, axis), dtype=float)
    except Exception:  # the checks say what is wrong
        return None
    if got.shape != (3, 3) or np.allclose(got, msd.rotation_matrix(angle, axis), atol=1e-12):
        return None
    return matching_variant(got, matrix_mistakes(angle, axis), rtol=1e-9)


def layout_mistakes(grid, angle, axis):
    """Positions that typical mistakes in rotate_layout(grid, angle, axis) give, by cause."""
    rotation = msd.rotation_matrix(angle, axis)
    centroid = grid.reshape(-1, 3).mean(axis=0)
    return {
        "rotating about the origin instead of the centroid: subtract the mean position "
        "first and add it back": grid @ rotation.T,
        "x @ R rotates by -angle; row vectors need x @ R.T": (
            (grid - centroid) @ rotation + centroid
        ),
        "the angle argument is ignored (always 45°)": (
            (grid - centroid) @ msd.rotation_matrix(45.0, axis).T + centroid
        ),
        "the mean of all coordinates (points.mean()) taken as the centroid: rotate every "
        "position p to R (p - c) + c, c the centroid, the mean position points.mean(axis=0)": (
            (grid - grid.mean()) @ rotation.T + grid.mean()
        ),
    }


@functools.lru_cache(maxsize=16)
def layout_mistake(task3):
    """The typical mistake the student's rotate_layout is recognised as (a 3 × 4 × 2 grid turned
    -30° about (1, 1, 0)), that of its rotation_matrix where that is wrong, or None."""
    grid = oracles.template_positions((3, 4, 2), 0.1, (-1.0, 1.5, -1.0))
    axis, angle = (1.0, 1.0, 0.0), -30.0
    try:
        got = np.asarray(task3.rotate_layout(grid.copy(), angle, axis), dtype=float)
    except Exception:  # the checks say what is wrong
        return None
    centroid = grid.reshape(-1, 3).mean(axis=0)
    right = (grid - centroid) @ msd.rotation_matrix(angle, axis).T + centroid
    if got.shape != grid.shape or relative_error(got, right) < 1e-12:
        return None
    return matching_variant(got, layout_mistakes(grid, angle, axis)) or matrix_mistake(task3)


def matrix_at_fault(task3, angle, axis):
    """Why rotate_layout may be wrong because rotation_matrix is, or None."""
    try:
        got = np.asarray(task3.rotation_matrix(angle, axis), dtype=float)
    except Exception as error:
        return f"your rotation_matrix fails ({type(error).__name__}), and rotate_layout uses it"
    if got.shape != (3, 3) or not np.allclose(got, msd.rotation_matrix(angle, axis), atol=1e-9):
        return "your rotation_matrix is wrong (see its check), and rotate_layout uses it"
    return None


def rotation_at_fault(task3):
    """Why drop_rotated_cube may be wrong because of another function of the task (the mistake
    recognised in it, `layout_mistake`, where there is one), or None."""
    recognised = layout_mistake(task3)
    if recognised:
        return recognised
    grid = oracles.template_positions((2, 3, 2), 0.5, (0.0, 1.0, 0.0))
    try:
        got = np.asarray(task3.rotate_layout(grid.copy(), 45.0, (0.0, 0.0, 1.0)), dtype=float)
    except Exception as error:
        return f"your rotate_layout fails ({type(error).__name__}), and the cube is turned by it"
    centroid = grid.reshape(-1, 3).mean(axis=0)
    turned = (grid - centroid) @ msd.rotation_matrix(45.0, (0.0, 0.0, 1.0)).T + centroid
    if got.shape != grid.shape or not np.allclose(got, turned, atol=1e-9):
        return (
            "your rotate_layout does not turn the layout right (see its check), and the "
            "cube is turned by it"
        )
    return None


def student_acceleration(task3, positions, springs, rest, stiffness):
    got = task3.spring_acceleration(positions.copy(), springs.copy(), rest.copy(), stiffness)
    return as_array(got, "spring_acceleration", positions.shape)


@pytest.mark.points(2)
def test_rotation_matrix_right_handed(task3):
    """rotation_matrix(angle, axis) is a right-handed rotation, for an axis of any length."""
    x, y = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    quarter = as_array(task3.rotation_matrix(90.0, (0.0, 0.0, 1.0)), "rotation_matrix", (3, 3))
    expect(
        np.allclose(quarter @ x, y, atol=1e-12),
        saw=f"rotation_matrix(90, (0, 0, 1)) turns the x axis into {vec(quarter @ x)}; a "
        "right-handed quarter turn about z takes x to y",
        cause=matrix_mistake(task3)
        or "the transpose (a left-handed turn: the sign of the sin terms) or radians "
        "where degrees are given (use np.radians)",
    )
    for axis in AXES:
        for angle in (30.0, -58.3, 180.0):
            got = as_array(task3.rotation_matrix(angle, axis), "rotation_matrix", (3, 3))
            expected = msd.rotation_matrix(angle, axis)
            own = matching_variant(got, matrix_mistakes(angle, axis), rtol=1e-9)
            mistake = own and (matrix_mistake(task3) or own)
            expect(
                np.allclose(got, expected, atol=1e-12),
                saw=f"rotation_matrix({angle}, {axis}) has R Rᵀ = I off by "
                f"{num(np.max(np.abs(got @ got.T - np.eye(3))))} and differs from the "
                f"rotation by {angle}° about {axis} by {num(np.max(np.abs(got - expected)))}",
                cause=mistake
                or "Rodrigues' formula with the unit axis n: "
                "cos θ I + sin θ [n]× + (1 - cos θ) n nᵀ",
            )


@pytest.mark.points(2)
def test_rotate_layout_turns_about_centroid(task3):
    """rotate_layout keeps the shape of the array, the centroid and every distance."""
    grid = oracles.template_positions((3, 4, 2), 0.1, (-1.0, 1.5, -1.0))
    for axis, angle in (((0.0, 0.0, 1.0), 45.0), ((1.0, 1.0, 0.0), -30.0)):
        got = as_array(task3.rotate_layout(grid.copy(), angle, axis), "rotate_layout", grid.shape)
        centroid = grid.reshape(-1, 3).mean(axis=0)
        expected = (grid - centroid) @ msd.rotation_matrix(angle, axis).T + centroid
        mistake = layout_mistake(task3) or matching_variant(got, layout_mistakes(grid, angle, axis))
        moved = got.reshape(-1, 3).mean(axis=0) - centroid
        expect(
            relative_error(got, expected) < 1e-12,
            saw=f"rotate_layout(grid, {angle}, {axis}) moved the centroid by {vec(moved)} and "
            f"puts particles up to {num(np.max(np.abs(got - expected)))} away from the rotated "
            "grid",
            cause=mistake
            or matrix_at_fault(task3, angle, axis)
            or "rotate every position p to R (p - c) + c, c the centroid",
        )


def sum_mistakes(x, springs, rest, stiffness, task3):
    """Accelerations that typical mistakes in spring_acceleration give, by cause."""
    expected = oracles.spring_acceleration(oracles.spring_body(x, springs, rest, stiffness), x)
    last_wins = np.zeros_like(x)
    f = oracles.force_of_each_spring(x, springs, rest, stiffness)
    last_wins[springs[:, 0]] += f  # repeated indices: only one spring per particle counts
    last_wins[springs[:, 1]] -= f
    return {
        "a[i] += f with repeated indices keeps only one spring per particle; use "
        "np.add.at or np.bincount (or a loop) to add every spring": last_wins,
        "the sign of (l - |x_i - x_j|) or of the direction x_i - x_j": -expected,
        **oracles.spring_list_mistakes(x, springs, rest, stiffness, task3),
    }


@functools.lru_cache(maxsize=16)
def sum_mistake(task3):
    """The typical mistake the student's spring_acceleration is recognised as (a deformed
    3 × 4 × 2 jelly with 1, √2, √3 springs and k = 0.7, no template's number), or None."""
    rng = np.random.default_rng(13)
    body = jelly(stiffness=0.7)
    x = body.positions + 0.05 * rng.standard_normal(body.positions.shape)
    springs, rest = springs_of(body)
    try:
        got = np.asarray(task3.spring_acceleration(x.copy(), springs, rest, 0.7), dtype=float)
    except Exception:  # the checks say what is wrong
        return None
    if got.shape != x.shape or relative_error(got, oracles.spring_acceleration(body, x)) < 1e-9:
        return None
    return matching_variant(got, sum_mistakes(x, springs, rest, 0.7, task3))


def named(task3, got, x, springs, rest, stiffness):
    """The mistake a check names where its accelerations ``got`` are what a typical mistake
    gives: the one recognised in the student's spring_acceleration (`sum_mistake`, named
    alike by every check), else its own; None where ``got`` is no typical mistake's."""
    own = matching_variant(got, sum_mistakes(x, springs, rest, stiffness, task3))
    return own and (sum_mistake(task3) or own)


def compare_with_engine(task3, got, body, x, what):
    expected = oracles.spring_acceleration(body, x)
    error = relative_error(got, expected)
    if error < 1e-9:
        return
    springs, rest = springs_of(body)
    worst = int(np.argmax(np.linalg.norm(got - expected, axis=1)))
    mistake = named(task3, got, x, springs, rest, body.edges().stiffness[0])
    expect(
        False,
        saw=f"{what}: particle {worst} gets a = {vec(got[worst])}, eq. (1.1)-(1.2) give "
        f"{vec(expected[worst])} (largest error {percent(error)})",
        cause=mistake or "sum f_ij over every spring of the particle, as eq. (1.1) says",
    )


@pytest.mark.points(3)
def test_spring_acceleration_matches_equations(task3):
    """On a rotated, deformed jelly (1, √2, √3 springs) every particle gets eq. (1.1)-(1.2)."""
    rng = np.random.default_rng(11)
    body = jelly()
    body.rotate(msd.rotation_matrix(58.3, (0, 0, 1)))
    x = body.positions + 0.05 * rng.standard_normal(body.positions.shape)
    springs, rest = springs_of(body)
    got = student_acceleration(task3, x, springs, rest, 0.5)
    compare_with_engine(task3, got, body, x, "on a rotated, deformed 3 × 4 × 2 jelly")


@pytest.mark.points(2)
@settings(max_examples=15)
@given(seed=st.integers(0, 2**32 - 1))
def test_same_physics_in_any_orientation(task3, seed):
    """Any rotation of a body at rest leaves it force-free; for a deformed body a(Rx) = R a(x)."""
    rng = np.random.default_rng(seed)
    rotation = oracles.random_rotation(rng)
    body = jelly()
    springs, rest = springs_of(body)
    at_rest = body.positions @ rotation.T
    a_rest = student_acceleration(task3, at_rest, springs, rest, 0.5)
    expect(
        np.max(np.abs(a_rest)) < 1e-9,
        saw=f"a rotated body at rest feels accelerations up to {num(np.max(np.abs(a_rest)))}",
        cause=sum_mistake(task3)
        or "a rest length or a force direction that depends on the coordinate axes",
    )
    x = body.positions + 0.05 * rng.standard_normal(body.positions.shape)
    a = student_acceleration(task3, x, springs, rest, 0.5)
    expect_nontrivial(a, x, "spring_acceleration of a deformed jelly")
    turned = student_acceleration(task3, x @ rotation.T, springs, rest, 0.5)
    error = relative_error(turned, a @ rotation.T)
    expect(
        error < 1e-9,
        saw=f"rotating a deformed body changes its accelerations by {percent(error)} beyond "
        "the rotation itself: the physics depends on the orientation",
        cause=sum_mistake(task3)
        or "using coordinate axes instead of the spring direction x_i - x_j",
    )


@pytest.mark.points(1)
def test_no_net_force_or_torque(task3):
    """The spring forces of a deformed body add up to zero force and zero torque."""
    rng = np.random.default_rng(12)
    body = jelly()
    x = body.positions + 0.1 * rng.standard_normal(body.positions.shape)
    springs, rest = springs_of(body)
    a = student_acceleration(task3, x, springs, rest, 0.5)
    expect_nontrivial(a, x, "spring_acceleration of a deformed jelly")
    scale = float(np.max(np.abs(a)))
    net = a.sum(axis=0)
    torque = np.cross(x - x.mean(axis=0), a).sum(axis=0)
    expect(
        np.linalg.norm(net) <= 1e-9 * scale * len(x),
        saw=f"the springs give the body a net acceleration {vec(net)} (each ~{num(scale)})",
        cause=sum_mistake(task3) or "the reaction -f_ij on particle j is missing or added twice",
    )
    expect(
        np.linalg.norm(torque) <= 1e-9 * scale * len(x),
        saw=f"the springs give the body a net torque {vec(torque)}",
        cause=sum_mistake(task3) or "forces not along the spring direction x_i - x_j",
    )


@pytest.mark.points(3)
def test_tilted_cube_collapses_upright_one_stands(task3):
    """Axis springs only: tilted 45° about z the cube folds flat; turned 45° about y it stands."""
    for axis, angle, collapses in (((0.0, 0.0, 1.0), 45.0, True), ((0.0, 1.0, 0.0), 45.0, False)):
        got = cube_ratio(task3, angle, axis, (1,))
        if collapses:
            expect(
                got < 0.3,
                saw=f"a cube with axis springs only, tilted {angle}° about {axis}, kept "
                f"{percent(got)} of its thickness",
                cause=lambda: (
                    rotation_at_fault(task3)
                    or "a different experiment: the template's undamped scheme msd.Verlet() (the "
                    "damping of eq. (1.4) is task 5's), dt = DT, the steps asked for, gravity and "
                    "the floor; or springs beyond the 6 axis neighbours"
                ),
            )
        else:
            expect(
                got > 0.9,
                saw=f"a cube turned {angle}° about the vertical axis {axis} kept only "
                f"{percent(got)} of its thickness; its springs still carry gravity vertically",
                cause=lambda: rotation_at_fault(task3) or "rotating about the wrong axis",
            )
