"""Checks of task 5: Verlet with damping, eq. (1.3)-(1.4), as an engine integrator."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

import msdlab as msd
from msdlab.course import oracles
from msdlab.course.feedback import (
    as_array,
    expect,
    matching_variant,
    num,
    percent,
    returned,
    vec,
)
from msdlab.course.reference_cache import cached

pytestmark = pytest.mark.task5

GRAVITY = oracles.TEMPLATE_GRAVITY


def jelly(n=3, spacing=None, origin=(0.0, 0.0, 0.0)):
    spacing = 2.0 / n if spacing is None else spacing
    return oracles.grid_body((n, n, n), spacing, 0.5, (1, 2, 3), origin)


@cached  # the same for every submission: computed once per grading run
def jelly_limit(damping: float) -> float:
    """The engine's predicted stable dt (s) of msd.Verlet(damping) for jelly()."""
    return msd.max_stable_dt(jelly(), msd.Verlet(damping))


def one_step_case(seed=0):
    """A small deformed, moving body with springs and gravity, and its dynamics."""
    rng = np.random.default_rng(seed)
    body = oracles.grid_body((2, 3, 2), 0.5, 0.5, (1, 2, 3), (0.0, 2.0, 0.0))
    x = body.positions + 0.05 * rng.standard_normal(body.positions.shape)
    v = 0.1 * rng.standard_normal(x.shape)
    return msd.Dynamics(body, [msd.Gravity(GRAVITY)]), x, v


def engine_step(lam, x, v, dt, dynamics):
    """x(t + dt) by the engine's Verlet with damping λ, eq. (1.4)."""
    return msd.Verlet(lam).step(x.copy(), v.copy(), dt, dynamics)[0]


WHOLE_UPDATE = (
    "damping applied to the whole update, (1 - λ)(2 x(t) - x(t - dt) + a dt²) + λ x(t): "
    "eq. (1.4) damps only the motion x(t) - x(t - dt), the force's a(t) dt² is not damped"
)


def step_mistakes(x, v, dt, lam, dynamics):
    """New positions that typical mistakes give, from the engine's steps (λ = 0 and λ)."""
    kick = dynamics.acceleration(x, v) * dt**2  # a(t)·dt²
    undamped = engine_step(0.0, x, v, dt, dynamics)  # 2 x(t) - x(t - dt) + a dt²
    damped = engine_step(lam, x, v, dt, dynamics)
    return {
        "explicit Euler (x + dt·v), not eq. (1.4)": x + dt * v,
        "λ is ignored: this is eq. (1.3)": undamped,
        "damping applied to the acceleration term, (1 - λ) a dt², instead of to x(t) and "
        "x(t - dt)": undamped - lam * kick,
        WHOLE_UPDATE: damped - lam * kick,
        "damping applied to the positions, (1 - λ)(2 x(t) - x(t - dt)): it pulls "
        "particles towards the origin": (1 - lam) * (undamped - kick) + kick,
        "the signs of λ reversed: (2 + λ) x(t) - (1 + λ) x(t - dt) adds energy": (
            2 * undamped - damped
        ),
        # the forces of these checks do not depend on v: reversing it only moves x(t - dt)
        "x(t - dt) taken as x + v·dt instead of x - v·dt": engine_step(lam, x, -v, dt, dynamics),
    }


@functools.lru_cache(maxsize=16)  # per task module: the checks of one submission ask often
def scheme_mistake(task5, lam=0.3):
    """The typical mistake the student's DampedVerlet(λ).step is recognised as (one step of a
    deformed, moving body under springs and gravity), or None.

    A check that runs the integrator names it as the cause of its failure, so the report
    names the one mistake once; a mistake that gives the right step at this λ (λ ignored,
    at λ = 0) is no cause.
    """
    dynamics, x, v = one_step_case(2)
    dt = 0.4
    try:
        got = np.asarray(task5.DampedVerlet(lam).step(x.copy(), v.copy(), dt, dynamics)[0], float)
    except Exception:  # the checks of the step say what is wrong
        return None
    right = engine_step(lam, x, v, dt, dynamics)
    mistakes = {
        cause: values
        for cause, values in step_mistakes(x, v, dt, lam, dynamics).items()
        if not np.allclose(values, right, rtol=1e-9, atol=1e-14)
    }
    return matching_variant(got, mistakes, rtol=1e-9) if got.shape == x.shape else None


def damped_verlet(task5, lam):
    """The student's DampedVerlet(λ) for a valid λ, or a failure naming the refusal."""
    try:
        return task5.DampedVerlet(lam)
    except ValueError as error:
        expect(
            False,
            saw=f"DampedVerlet({lam}) refused a valid damping: {error}",
            cause="a range check that excludes valid values: 0 <= λ < 1 is allowed (λ = 0 is "
            "the template's undamped scheme)",
        )


def check_one_step(task5, lam, cause=""):
    """One step of a deformed, moving body with λ: eq. (1.4) and v = (x(t+dt) - x(t))/dt."""
    dt = 0.4
    dynamics, x, v = one_step_case()
    expected = engine_step(lam, x, v, dt, dynamics)
    result = returned(
        damped_verlet(task5, lam).step(x.copy(), v.copy(), dt, dynamics), "DampedVerlet.step"
    )
    expect(
        isinstance(result, tuple) and len(result) == 2,
        saw=f"step returned {type(result).__name__}, not the pair (x_new, v_new)",
    )
    x_new = as_array(result[0], "step (new positions)", x.shape)
    v_new = as_array(result[1], "step (new velocities)", x.shape)
    worst = int(np.argmax(np.linalg.norm(x_new - expected, axis=1)))
    mistakes = step_mistakes(x, v, dt, lam, dynamics)
    if lam == 0:  # the damping's mistakes are no mistakes without damping
        mistakes = {k: m for k, m in mistakes.items() if not np.allclose(m, expected, 1e-9)}
    expect(
        np.allclose(x_new, expected, rtol=1e-12, atol=1e-14),
        saw=f"with λ = {lam}, dt = {dt}: particle {worst} moves to {vec(x_new[worst], 6)}, "
        f"eq. (1.4) gives {vec(expected[worst], 6)}",
        cause=matching_variant(x_new, mistakes, rtol=1e-9) or cause,
    )
    expect(
        np.allclose(v_new, (expected - x) / dt, rtol=1e-9, atol=1e-14),
        saw=f"with λ = {lam} the returned velocity of particle 0 is {vec(v_new[0])}, but "
        f"(x(t+dt) - x(t))/dt = {vec((expected[0] - x[0]) / dt)}",
        cause="returning the old velocity, or a central difference: the next step "
        "recovers x(t) as x(t+dt) - v·dt, so v must be (x(t+dt) - x(t))/dt",
    )


@pytest.mark.points(2)
def test_one_step_is_equation_1_3(task5):
    """Without damping one step is eq. (1.3), x(t+dt) = 2x(t) - x(t-dt) + a(t)dt², and the
    velocity returned is (x(t+dt) - x(t))/dt."""
    check_one_step(
        task5,
        0.0,
        "x(t - dt) = x - v·dt from the velocity the step was given, a(t) = "
        "dynamics.acceleration(x, v), and x(t+dt) = 2 x(t) - x(t - dt) + a(t) dt²",
    )


@pytest.mark.points(2)
def test_one_step_is_equation_1_4(task5):
    """With damping one step is x(t+dt) = (2-λ)x(t) - (1-λ)x(t-dt) + a(t)dt²."""
    cause = (
        "the λ terms of eq. (1.4): (2 - λ) x(t) - (1 - λ) x(t - dt) + a(t) dt², the force's "
        "a(t) dt² undamped"
        if step_is_right(task5, 0.0)
        else "the step is not eq. (1.3) without damping either (see one_step_is_equation_1_3)"
    )
    for lam in (0.3, 0.9):
        check_one_step(task5, lam, cause)


def step_is_right(task5, lam):
    """Whether the student's DampedVerlet(λ) takes the right step in `check_one_step`."""
    try:
        check_one_step(task5, lam)
    except Exception:
        return False
    return True


@pytest.mark.points(2)
def test_velocity_dependent_forces_see_the_velocity(task5):
    """With dashpots and drag, a(t) depends on v: the step must use a(x, v) with the given v
    (λ = 0: this check is about the acceleration, not the damping)."""
    dt, lam = 0.2, 0.0
    rng = np.random.default_rng(5)
    body = msd.Body.grid((2, 2, 3), 0.5, 0.5, neighbours=(1, 2), damping=0.4)
    x = body.positions + 0.05 * rng.standard_normal(body.positions.shape)
    v = rng.standard_normal(x.shape)
    dynamics = msd.Dynamics(body, [msd.Gravity(GRAVITY), msd.ViscousDamping(0.3)])
    expected = engine_step(lam, x, v, dt, dynamics)
    result = returned(
        task5.DampedVerlet(lam).step(x.copy(), v.copy(), dt, dynamics), "DampedVerlet.step"
    )
    x_new = as_array(result[0], "step")
    still = np.zeros_like(v)
    mistakes = {
        "the acceleration evaluated at zero velocity, a(x, 0): dashpots and drag depend on "
        "v, pass the velocity you were given": (
            (2 - lam) * x - (1 - lam) * (x - v * dt) + dynamics.acceleration(x, still) * dt**2
        ),
        "x(t - dt) taken as x + v·dt instead of x - v·dt": (
            (2 - lam) * x - (1 - lam) * (x + v * dt) + dynamics.acceleration(x, v) * dt**2
        ),
    }
    expect(
        np.allclose(x_new, expected, rtol=1e-12, atol=1e-14),
        saw=f"with dashpots and drag (forces that depend on v), λ = {lam}, dt = {dt}: new "
        f"positions off by up to {num(np.max(np.abs(x_new - expected)))}",
        cause=matching_variant(x_new, mistakes, rtol=1e-9)
        or scheme_mistake(task5, lam)
        or "a(t) = dynamics.acceleration(x, v) with the x and v the step was given",
    )


@pytest.mark.points(3)
def test_no_damping_reproduces_the_template(task5, own_numbers):
    """λ = 0 reproduces the template's falling grid step for step (to rounding), floor included
    (the grid of task 1, dropped from the student's own height under their own acceleration
    where each student has their own numbers)."""
    shape, spacing, origin = (3, 2, 4), 0.1, (-1.0, own_numbers.bottom, -1.0)
    gravity = (0.0, own_numbers.gravity, 0.0)
    start = oracles.template_positions(shape, spacing, origin).reshape(-1, 3)
    landing = template_landing(own_numbers.bottom, own_numbers.gravity)
    steps = landing + 50
    template = oracles.template_run(start, steps, acceleration=gravity)
    body = msd.Body.grid(shape, spacing, neighbours=(), origin=origin)
    forces = [msd.Gravity(gravity), msd.Ground(0.0)]
    frames = (
        msd.Simulation(body, task5.DampedVerlet(0.0), oracles.TEMPLATE_DT, forces)
        .run(steps=steps)
        .positions
    )
    error = np.max(np.abs(frames - template), axis=(1, 2))
    tolerance = 1e-9  # rounding only: another order of the same arithmetic differs by ~1e-12
    first = int(np.argmax(error > tolerance))
    expect(
        np.all(error <= tolerance),
        saw=f"with λ = 0 the grid leaves the template's trajectory in step {first} (off by "
        f"{num(error[first])}; dropped from y = {own_numbers.bottom}, its bottom layer meets "
        f"the floor in step {landing})",
        cause="a scheme other than eq. (1.3), or a different start: the template begins with "
        "old = current (zero velocity)"
        if first < landing
        else "a velocity that is not (x(t+dt) - x(t))/dt: the floor edits it and the next "
        "step must recover x(t - dt) from it",
    )


def template_landing(bottom: float, g: float) -> int:
    """The step in which the template's grid, its bottom layer at rest at height ``bottom``
    under the acceleration (0, ``g``, 0), first reaches the floor (task 1's answer)."""
    height, speed, step = bottom, 0.0, 0
    while height > 0.0:
        speed += g * oracles.TEMPLATE_DT**2  # the template's distance per step grows by g dt²
        height += speed
        step += 1
    return step


@pytest.mark.points(2)
def test_damping_outside_0_to_1_is_refused(task5):
    """λ must be in [0, 1): λ < 0 adds energy, λ >= 1 flips or freezes the motion."""
    for lam in (-0.1, 1.0, 1.2, math.nan):
        try:
            task5.DampedVerlet(lam)
        except ValueError:
            continue
        expect(
            False,
            saw=f"DampedVerlet({lam}) was accepted",
            cause="no range check: raise ValueError unless 0 <= λ < 1 (λ = 1.2 reverses the "
            "velocity every step; NaN fails every comparison, so test 'not 0 <= λ < 1')",
        )
    for lam in (0.0, 0.01, 0.99):
        try:
            task5.DampedVerlet(lam)
        except ValueError as error:
            expect(
                False,
                saw=f"DampedVerlet({lam}) was refused ({error})",
                cause="a range check that excludes valid values: 0 <= λ < 1 is allowed, "
                "λ = 0 being no damping at all",
            )


def energy_history(integrator, dt_fraction=0.2, steps=400):
    """Total energies of a kicked 3³ jelly run with ``integrator``, and dt, limit."""
    body = jelly()
    limit = jelly_limit(0.0)
    rng = np.random.default_rng(7)
    body.positions = body.positions + 0.02 * rng.standard_normal(body.positions.shape)
    dt = dt_fraction * limit
    frames = msd.Simulation(body, integrator, dt).run(steps=steps).positions
    return oracles.energies(body, frames, dt), dt, limit


@pytest.mark.points(3)
def test_damping_removes_energy(task5):
    """λ = 0 keeps the total energy of a wobbling jelly; λ = 0.01 takes it out steadily."""
    energy, dt, limit = energy_history(task5.DampedVerlet(0.0))
    drift = float(np.max(np.abs(energy - energy[0])) / energy[0])
    expect(
        drift < 0.03,
        saw=f"without damping the total energy changed by up to {percent(drift)} in "
        f"{len(energy) + 1} steps at dt = {num(dt)} (the predicted stable limit is "
        f"{num(limit)})",
        cause=scheme_mistake(task5, 0.0)
        or "a first-order scheme (Euler) instead of eq. (1.3), or damping applied when λ = 0",
    )
    energy, dt, limit = energy_history(task5.DampedVerlet(0.01))
    samples = energy[::10]
    growth = float(np.max(np.diff(samples)) / energy[0])
    left = float(energy[-1] / energy[0])
    expect(
        growth < 0.01 and left < 0.05,
        saw=f"with λ = 0.01 the total energy rose by up to {percent(max(growth, 0.0))} between "
        f"samples and {percent(left)} of it is left after {len(energy) + 1} steps at "
        f"dt = {num(dt)}; velocity damping of 1 % per step should leave about "
        f"{percent((1 - 0.01) ** (2 * len(energy)))}",
        cause=scheme_mistake(task5)
        or "damping applied to the wrong term (the acceleration or the positions) or "
        "with the wrong sign",
    )


@pytest.mark.points(2)
def test_damping_acts_on_velocity_only(task5):
    """A free particle at rest stays put; a moving one keeps its direction, speed ×(1-λ) a step;
    under a force a, v(t+dt) = (1-λ)v + a·dt: the force's share is not damped."""
    lam, dt = 0.3, 0.5
    body = msd.Body.from_arrays([[5.0, 3.0, -2.0], [0.0, 1.0, 0.0]])
    x = body.positions.copy()
    v = np.array([[0.0, 0.0, 0.0], [1.0, -2.0, 0.5]])
    integrator = task5.DampedVerlet(lam)
    x, v = check_free_particles(task5, integrator, msd.Dynamics(body), x, v, lam, dt)
    pull = np.array([0.2, -0.5, 0.1])
    dynamics = msd.Dynamics(body, [msd.Gravity(pull)])
    for _ in range(5):
        x_new, v_new = returned(integrator.step(x, v.copy(), dt, dynamics), "DampedVerlet.step")
        v_new = as_array(v_new, "step", x.shape)
        expected = (1 - lam) * v + pull * dt
        worst = int(np.argmax(np.linalg.norm(v_new - expected, axis=1)))
        expect(
            np.allclose(v_new, expected, rtol=1e-9, atol=1e-12),
            saw=f"a particle moving at {vec(v[worst])} under a constant acceleration "
            f"{vec(pull)} continues at {vec(v_new[worst])} with λ = {lam}, dt = {dt}; eq. (1.4) "
            f"gives (1 - λ) v + a dt = {vec(expected[worst])}",
            cause=scheme_mistake(task5)
            or "λ applied to the force's term too: eq. (1.4) damps x(t) - x(t - dt) only, "
            "a(t) dt² is added undamped",
        )
        x, v = as_array(x_new, "step", x.shape), v_new


def check_free_particles(task5, integrator, dynamics, x, v, lam, dt):
    """Five steps of free particles: at rest they stay, moving they slow down by (1 - λ) a
    step, and the velocity array given is left alone. Returns the last x and v."""
    for _ in range(5):
        given = v.copy()
        x_new, v_new = returned(integrator.step(x, given, dt, dynamics), "DampedVerlet.step")
        x_new, v_new = as_array(x_new, "step", x.shape), as_array(v_new, "step", x.shape)
        expect(
            np.array_equal(given, v),
            saw="step changed the velocity array it was given",
            cause="in-place updates such as v *= 1 - λ: the caller's velocities are corrupted",
        )
        expect(
            np.allclose(x_new[0], x[0], atol=1e-12),
            saw=f"a free particle at rest at {vec(x[0])} moved to {vec(x_new[0])} with λ = {lam}",
            cause=scheme_mistake(task5)
            or "damping applied to the positions, (1 - λ)·x, which pulls particles towards "
            "the origin; eq. (1.4) damps only the difference x(t) - x(t - dt)",
        )
        expected = (1 - lam) * v[1]
        expect(
            np.allclose(v_new[1], expected, rtol=1e-9),
            saw=f"a free particle moving at {vec(v[1])} continues at {vec(v_new[1])} with "
            f"λ = {lam}; eq. (1.4) gives {vec(expected)}",
            cause=scheme_mistake(task5) or "λ applied to the wrong term or with the wrong sign",
        )
        x, v = x_new, v_new
    return x, v


@pytest.mark.points(2)
def test_predicted_stability_limit(task5):
    """The largest stable dt of a mode ω is √(4 - 2λ)/ω, as for the engine's Verlet."""
    omega = 2.0
    for lam in (0.0, 0.5):
        got = msd.stability_limit(task5.DampedVerlet(lam), msd.Mode(omega))
        expected = math.sqrt(4 - 2 * lam) / omega
        expect(
            abs(got - expected) < 1e-6 * expected,
            saw=f"with λ = {lam} your integrator is stable up to dt = {num(got, 6)} for a mode "
            f"ω = {omega}; eq. (1.4) is stable up to √(4 - 2λ)/ω = {num(expected, 6)}",
            cause=scheme_mistake(task5, lam)
            or ("explicit Euler: unstable at any dt without damping" if got == 0 else "")
            or "a scheme other than eq. (1.4)",
        )


@pytest.mark.points(2)
def test_measured_stable_dt_as_predicted(task5):
    """measured_stable_dt(λ) agrees with the engine's prediction for your DampedVerlet(λ) (for
    eq. (1.4): √(4 - 2λ)/ω, smaller with damping); this check is about the measurement."""
    for lam in (0.0, 0.5):
        measured = float(returned(measurement(task5, lam), "measured_stable_dt"))
        predicted, whose = own_limit(task5, lam)
        expect(
            abs(measured / predicted - 1) < 0.06,
            saw=f"with λ = {lam} you measured a largest stable dt of {num(measured)}, the "
            f"predicted limit of {whose} is {num(predicted)}",
            cause="a different body than jelly(n), a measurement that does not use your "
            "DampedVerlet, or the damping λ is not passed on",
        )


def measurement(task5, lam):
    """The student's measured_stable_dt(λ, 3, 300, 0.01); where it fails while their
    DampedVerlet has a recognised mistake (unstable at any dt, nothing can be measured), a
    failure naming that mistake."""
    try:
        return task5.measured_stable_dt(lam, 3, 300, 0.01)
    except Exception as error:
        mistake = scheme_mistake(task5, lam) or scheme_mistake(task5)
        if not mistake:
            raise
        expect(
            False,
            saw=f"measured_stable_dt({lam}, 3, 300, 0.01) fails ({type(error).__name__}: "
            f"{error}): your DampedVerlet({lam}) is what is measured",
            cause=mistake,
        )


def own_limit(task5, lam, n=3):
    """The engine's predicted stable dt of jelly(n) run with the student's DampedVerlet(λ), and
    whose it is; eq. (1.4)'s where the student's integrator cannot be analysed."""
    body = jelly(n)
    try:
        limit = msd.max_stable_dt(body, task5.DampedVerlet(lam))
    except Exception:  # the checks of the step say what is wrong
        limit = 0.0
    if math.isfinite(limit) and limit > 0:
        return limit, f"your DampedVerlet({lam})"
    return msd.max_stable_dt(body, msd.Verlet(lam)), "eq. (1.4), √(4 - 2λ)/ω"
