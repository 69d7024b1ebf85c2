"""Instructor-only checks of task 5 (left out of the student release)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_task5 import engine_step, own_limit, scheme_mistake, step_mistakes

import msdlab as msd
from msdlab.course.feedback import as_array, expect, num

import reference_hidden as reference

pytestmark = [pytest.mark.task5, pytest.mark.hidden]


@pytest.mark.points(2)
@settings(max_examples=30, deadline=None)  # its first example finds the mistake
@given(
    n=st.integers(1, 6),
    dim=st.sampled_from((2, 3)),
    lam=st.floats(0.0, 0.95),
    dt=st.floats(1e-3, 1.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_one_step_in_2d_and_3d(task5, n, dim, lam, dt, seed):
    """Eq. (1.4) holds for any number of particles, 2-D or 3-D, any λ in [0, 1) and dt."""
    rng = np.random.default_rng(seed)
    positions = rng.uniform(-1.0, 1.0, (n, dim))
    pairs = [(i, i + 1) for i in range(n - 1)]
    body = msd.Body.from_arrays(positions, np.array(pairs, dtype=int).reshape(-1, 2))
    gravity = (0.0, -1.0) if dim == 2 else (0.0, -1.0, 0.0)
    dynamics = msd.Dynamics(body, [msd.Gravity(gravity)])
    x = positions + 0.1 * rng.standard_normal(positions.shape)
    v = rng.standard_normal(positions.shape)
    kept = x.copy(), v.copy()
    x_new, v_new = task5.DampedVerlet(lam).step(x, v, dt, dynamics)
    x_new = as_array(x_new, "step (new positions)", x.shape)
    v_new = as_array(v_new, "step (new velocities)", x.shape)
    expected = same_scheme(task5, *kept, dt, lam, dynamics)
    expect(
        np.allclose(x_new, expected, rtol=1e-9, atol=1e-12),
        saw=f"{n} particles in {dim}-D, λ = {num(lam)}, dt = {num(dt)}: new positions off by "
        f"{num(np.max(np.abs(x_new - expected)))}",
        cause="code written for 3-D or for one particle only, or eq. (1.4) mistyped",
    )
    expect(
        np.allclose(v_new, (expected - kept[0]) / dt, rtol=1e-9, atol=1e-9),
        saw=f"the returned velocity is off by {num(np.max(np.abs(v_new * dt - expected + x)))}"
        f"·dt; it must be (x(t+dt) - x(t))/dt",
        cause="returning the old velocity or a central difference",
    )
    expect(
        np.array_equal(x, kept[0]) and np.array_equal(v, kept[1]),
        saw="step changed the x or v arrays it was given",
        cause="in-place updates (x += ...); return new arrays",
    )


def same_scheme(task5, x, v, dt, lam, dynamics):
    """x(t + dt) of eq. (1.4), or of the typical mistake the public checks recognised in the
    student's step: this check is about any number of particles and dimensions, and the
    mistake costs its points once, where it is named."""
    mistake = scheme_mistake(task5)
    if mistake is None:
        return engine_step(lam, x, v, dt, dynamics)
    return step_mistakes(x, v, dt, lam, dynamics)[mistake]


@pytest.mark.points(2)
def test_solved_setting_matches_the_engine(task5):
    """The solved setting (k = 0.5, λ = 0.01, dt = 0.4, 58.3° about z) runs as msd.Verlet."""
    got = reference.solved_setting(task5.DampedVerlet(0.01))
    error = float(np.max(np.abs(got - reference.solved_setting_verlet())))
    expect(
        error < 1e-9,
        saw=f"the solved setting drifts {num(error)} away from the engine's Verlet(0.01) in "
        "800 steps (floor contact included)",
        cause=scheme_mistake(task5)
        or "a velocity that is not (x(t+dt) - x(t))/dt, so the floor's edits are lost",
    )


@pytest.mark.points(1)
def test_measured_stable_dt_of_another_jelly(task5):
    """measured_stable_dt(λ, n) measures the jelly of n³ particles it is asked about."""
    measured = float(task5.measured_stable_dt(0.2, 2, 300, 0.01))
    predicted, whose = own_limit(task5, 0.2, n=2)
    expect(
        abs(measured / predicted - 1) < 0.06,
        saw=f"measured_stable_dt(0.2, n=2) = {num(measured)}, the 2³ jelly's predicted limit "
        f"with {whose} is {num(predicted)}",
        cause="n is ignored (measure jelly(n)), or the damping λ is not passed on",
    )
