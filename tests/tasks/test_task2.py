"""Checks of task 2: spring acceleration from the 6 axis neighbours, eq. (1.1)-(1.2)."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import msdlab as msd
from msdlab.course import oracles
from msdlab.course.feedback import (
    as_array,
    expect,
    expect_nontrivial,
    grid_place,
    matching_variant,
    num,
    percent,
    relative_error,
    vec,
)

pytestmark = pytest.mark.task2

SHAPE = (3, 4, 5)  # not a cube: a kernel that assumes n × n × n fails
SPACING = 0.1  # the template's 2/N for N = 20
STIFFNESS = 0.5


def perturbed_grid(shape, spacing, rng, amount=0.15):
    """A grid (nx, ny, nz, 3) with every particle moved randomly by ~amount·spacing."""
    x = oracles.template_positions(shape, spacing, (-1.0, 1.5, -1.0))
    return x + amount * spacing * rng.standard_normal(x.shape)


def expected_acceleration(x, spacing, stiffness):
    """The engine's spring acceleration of the axis-spring grid, (nx, ny, nz, 3)."""
    body = oracles.grid_body(x.shape[:3], spacing, stiffness, (1,))
    return oracles.spring_acceleration(body, x.reshape(-1, 3)).reshape(x.shape)


@functools.lru_cache(maxsize=16)  # per task module: the checks of one submission ask often
def kernel_mistake(task2):
    """The typical mistake the student's spring_acceleration is recognised as, or None: its
    accelerations of a deformed 3 × 4 × 5 grid of spacing 0.3 and k = 0.7 (numbers of no
    template, so an ignored argument shows) equal what the mistake gives, and no other's.

    Every check that fails names it as its cause, so the report names the one mistake once
    (`CheckReport.details`); a check's own diagnosis comes after it.
    """
    spacing, stiffness = 0.3, 0.7
    x = perturbed_grid(SHAPE, spacing, np.random.default_rng(3))
    try:
        got = np.asarray(task2.spring_acceleration(x.copy(), spacing, stiffness), dtype=float)
    except Exception:  # the checks say what is wrong
        return None
    if (
        got.shape != x.shape
        or relative_error(got, expected_acceleration(x, spacing, stiffness)) < 1e-9
    ):
        return None
    return matching_variant(got, oracles.axis_spring_mistakes(x, spacing, stiffness, task2))


def named(task2, got, x, spacing, stiffness):
    """The mistake a check names where its result ``got`` for ``x`` is what a typical mistake
    gives: the one recognised in the student's function (`kernel_mistake`, named alike by
    every check), else its own; None where ``got`` is no typical mistake's."""
    own = matching_variant(got, oracles.axis_spring_mistakes(x, spacing, stiffness, task2))
    return own and (kernel_mistake(task2) or own)


def student_acceleration(task2, x, spacing, stiffness):
    got = task2.spring_acceleration(x.copy(), spacing, stiffness)
    return as_array(got, "spring_acceleration", x.shape)


def compare_with_engine(task2, got, x, spacing, stiffness, what):
    """Fail with the worst particle and the typical mistake that explains the difference."""
    expected = expected_acceleration(x, spacing, stiffness)
    error = relative_error(got, expected)
    if error < 1e-9:
        return
    worst = np.unravel_index(np.argmax(np.linalg.norm(got - expected, axis=-1)), x.shape[:3])
    mistake = named(task2, got, x, spacing, stiffness)
    expect(
        False,
        saw=f"{what}: the {grid_place(worst, x.shape[:3])} gets a = {vec(got[worst])}, eq. "
        f"(1.1)-(1.2) give {vec(expected[worst])} (largest error {percent(error)} of the "
        "largest acceleration)",
        cause=mistake
        or "compare that particle's sum over its axis neighbours with eq. (1.2) by hand; "
        "check which neighbours your code visits there",
    )


@pytest.mark.points(2)
def test_grid_at_rest_feels_no_force(task2):
    """A grid at its rest spacing is free of stress: every acceleration is zero (and a
    deformed one is not)."""
    deformed = perturbed_grid(SHAPE, SPACING, np.random.default_rng(1))
    got = student_acceleration(task2, deformed, SPACING, STIFFNESS)
    expect_nontrivial(got, deformed, "spring_acceleration on a deformed grid")
    x = oracles.template_positions(SHAPE, SPACING, (-1.0, 1.5, -1.0))
    a = student_acceleration(task2, x, SPACING, STIFFNESS)
    worst = np.unravel_index(np.argmax(np.linalg.norm(a, axis=-1)), SHAPE)
    largest = float(np.linalg.norm(a[worst]))
    expect(
        largest <= 1e-9 * STIFFNESS * SPACING,
        saw=f"at rest (spacing h = {SPACING}) the {grid_place(worst, SHAPE)} is accelerated "
        f"by {vec(a[worst])}: the body is pre-stressed and would swell or shrink on its own",
        cause=kernel_mistake(task2)
        or "a rest length other than one grid spacing (e.g. 1 in world units instead of "
        "h = 2/N), or springs to particles that are not axis neighbours",
    )


@pytest.mark.points(2)
def test_stretched_pulls_compressed_pushes(task2):
    """Two particles: a stretched spring pulls them together, a compressed one pushes apart."""
    k, h = STIFFNESS, SPACING
    constant = oracles.task_constant(task2, "STIFFNESS")  # what ignoring the argument uses
    for factor, verb in ((1.5, "stretched"), (0.6, "compressed")):
        x = np.array([[[[0.0, 1.0, 0.0]]], [[[factor * h, 1.0, 0.0]]]])  # shape (2, 1, 1, 3)
        a = student_acceleration(task2, x, h, k)
        pull = k * (factor - 1.0) * h  # > 0: particle 0 moves towards +x
        expected = np.array([pull, 0.0, 0.0])
        expect(
            np.allclose(a[0, 0, 0], expected, rtol=1e-9, atol=1e-12)
            and np.allclose(a[1, 0, 0], -expected, rtol=1e-9, atol=1e-12),
            saw=f"a spring {verb} to {factor}·h between particles at x = 0 and x = "
            f"{num(factor * h)} gives accelerations {vec(a[0, 0, 0])} and {vec(a[1, 0, 0])}; "
            f"expected {vec(expected)} and {vec(-expected)}",
            cause=kernel_mistake(task2)
            or two_particle_cause(a[0, 0, 0], a[1, 0, 0], expected, factor * h, k, constant),
        )


def two_particle_cause(first, second, expected, length, stiffness, constant):
    """The usual cause of wrong accelerations of two particles joined by one spring of
    ``length`` and ``stiffness`` (the submission's STIFFNESS is ``constant``)."""
    if np.allclose(first, -expected) and np.allclose(second, expected):
        return "the sign of (l - |x_i - x_j|) or of the direction x_i - x_j"
    if np.allclose(first, expected) or np.allclose(second, -expected):
        return (
            "the reaction: f_ij added to particle i without -f_ij on j (j must get -f_ij, "
            "equal and opposite to f_ij on i)"
        )
    if np.allclose(first, -second) and first[0] * expected[0] > 0:
        return size_cause(first[0] / expected[0], length, stiffness, constant)
    return "the sign of (l - |x_i - x_j|), the rest length (one spacing h), or the stiffness"


def size_cause(ratio, length, stiffness, constant):
    """Why a spring force is ``ratio`` × eq. (1.2) for a spring of ``length`` and
    ``stiffness`` (the submission's STIFFNESS is ``constant``)."""
    ignored = constant is not None and not np.isclose(constant, stiffness)
    if ignored and np.isclose(ratio, constant / stiffness):
        return (
            f"the stiffness argument is ignored (your STIFFNESS = {constant:g} used instead "
            "of the k given)"
        )
    if np.isclose(ratio, 0.5):
        return (
            "half of each spring force: particle i gets all of f_ij and particle j all of "
            "-f_ij, not half each"
        )
    if np.isclose(ratio, length):
        return (
            "the direction x_i - x_j is not divided by the spring length |x_i - x_j| (it "
            "must be a unit vector)"
        )
    return (
        f"the size of the force is {num(ratio)}× eq. (1.2): check the stiffness k, the rest "
        "length (one spacing h), and that the direction is a unit vector"
    )


@pytest.mark.points(3)
def test_matches_equations_on_a_deformed_grid(task2):
    """On randomly deformed non-cubic grids every particle, border ones included, gets eq.
    (1.1)-(1.2)."""
    rng = np.random.default_rng(2)
    for shape in (SHAPE, (5, 2, 1), (1, 3, 2)):
        x = perturbed_grid(shape, SPACING, rng)
        got = student_acceleration(task2, x, SPACING, STIFFNESS)
        compare_with_engine(task2, got, x, SPACING, STIFFNESS, f"on a deformed {shape} grid")


@pytest.mark.points(2)
def test_forces_are_equal_and_opposite(task2):
    """Spring forces come in equal and opposite central pairs: no net force, no net torque."""
    rng = np.random.default_rng(4)
    x = perturbed_grid(SHAPE, SPACING, rng, amount=0.3)
    a = student_acceleration(task2, x, SPACING, STIFFNESS)
    expect_nontrivial(a, x, "spring_acceleration on a deformed grid")
    scale = float(np.max(np.linalg.norm(a, axis=-1)))
    net = a.reshape(-1, 3).sum(axis=0)
    expect(
        np.linalg.norm(net) <= 1e-9 * scale * a.size,
        saw=f"the springs give the whole body a net acceleration {vec(net)} (per-particle "
        f"accelerations ~{num(scale)}): the body would push itself through space",
        cause=kernel_mistake(task2)
        or "f_ij added to particle i without -f_ij on j, or a border neighbour counted from "
        "one side only",
    )
    r = x.reshape(-1, 3) - x.reshape(-1, 3).mean(axis=0)
    torque = np.cross(r, a.reshape(-1, 3)).sum(axis=0)
    expect(
        np.linalg.norm(torque) <= 1e-9 * scale * a.size,
        saw=f"the springs give the body a net torque {vec(torque)}: it would start spinning "
        "by itself",
        cause=kernel_mistake(task2)
        or "forces not along the spring: f_ij must point along x_i - x_j (divide by the "
        "length, do not use one coordinate axis as the direction)",
    )


@pytest.mark.points(2)
@settings(max_examples=15)
@given(seed=st.integers(0, 2**32 - 1))
def test_rotating_the_grid_rotates_the_forces(task2, seed):
    """Rotation invariance: for a rotated deformed grid, a(R x) = R a(x)."""
    rng = np.random.default_rng(seed)
    rotation = oracles.random_rotation(rng)
    x = perturbed_grid(SHAPE, SPACING, rng)
    a = student_acceleration(task2, x, SPACING, STIFFNESS)
    expect_nontrivial(a, x, "spring_acceleration on a deformed grid")
    rotated = student_acceleration(task2, x @ rotation.T, SPACING, STIFFNESS)
    error = relative_error(rotated, a @ rotation.T)
    expect(
        error < 1e-9,
        saw=f"after rotating the body the accelerations differ from the rotated accelerations "
        f"by {percent(error)}: the physics depends on how the body is oriented",
        cause=kernel_mistake(task2)
        or "code that uses a coordinate axis instead of the spring direction, e.g. "
        "k (h - (x_j - x_i)[0]) for x-neighbours; eq. (1.2) only uses distances and x_i - x_j",
    )


@pytest.mark.points(2)
def test_energy_is_conserved_in_a_verlet_run(task2):
    """A deformed spring grid run with velocity Verlet keeps its total energy (no gravity)."""
    rng = np.random.default_rng(5)
    shape, spacing = (3, 3, 4), 0.5
    x = perturbed_grid(shape, spacing, rng, amount=0.05)
    body = oracles.grid_body(shape, spacing, STIFFNESS, (1,))
    limit = msd.max_stable_dt(body, msd.VelocityVerlet())
    dt, steps = 0.1 * limit, 300
    flat = x.reshape(-1, 3)
    v = np.zeros_like(flat)

    def energy(positions, velocities):
        return 0.5 * np.sum(velocities**2) + msd.elastic_energy(body, positions)

    def acceleration(positions):
        got = task2.spring_acceleration(positions.reshape(*shape, 3), spacing, STIFFNESS)
        return as_array(got, "spring_acceleration", (*shape, 3)).reshape(-1, 3)

    start = energy(flat, v)
    a = acceleration(flat)
    expect_nontrivial(a, flat, "spring_acceleration on a deformed grid")
    for _ in range(steps):
        v_half = v + 0.5 * dt * a
        flat = flat + dt * v_half
        a = acceleration(flat)
        v = v_half + 0.5 * dt * a
    change = (energy(flat, v) - start) / start
    expect(
        abs(change) < 0.02,
        saw=f"total energy {'grew' if change > 0 else 'fell'} by {percent(abs(change))} in "
        f"{steps} velocity-Verlet steps at "
        f"dt = {num(dt)} (the predicted stable limit is {num(limit)}); it should stay within "
        "2 %",
        cause=kernel_mistake(task2)
        or "forces that are not the gradient of the spring energy: a wrong sign, a wrong "
        "rest length, or forces that are not equal and opposite",
    )
