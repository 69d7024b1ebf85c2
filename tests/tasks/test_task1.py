"""Checks of task 1: the template's falling grid and what its kernel really is."""

from __future__ import annotations

import math

import numpy as np
import pytest

import msdlab as msd
from msdlab.course import oracles
from msdlab.course.feedback import (
    Recognised,
    apart,
    as_array,
    expect,
    matching_variant,
    no_return,
    num,
    relative_error,
    returned,
)
from msdlab.course.reference_cache import cached

pytestmark = pytest.mark.task1

DT = oracles.TEMPLATE_DT


@cached  # the same for every submission: computed once per grading run
def free_fall_heights(y0: float, dt: float, g: float, steps: int) -> np.ndarray:
    """Heights (steps + 1,) of a particle falling from rest, run by the engine's Verlet."""
    body = msd.Body.from_arrays([[0.0, y0, 0.0]])
    simulation = msd.Simulation(body, msd.Verlet(), dt, [msd.Gravity((0.0, g, 0.0))])
    return simulation.run(steps=steps).positions[:, 0, 1]


@pytest.mark.points(1)
def test_particle_count(task1):
    """particle_count(n) is the number of particles of the template's n × n × n grid."""
    for n in (20, 30, 3):
        got = returned(task1.particle_count(n), f"particle_count({n})")
        expected = oracles.grid_body((n, n, n), 2.0 / n, 1.0).n_particles
        expect(
            got == expected,
            saw=f"particle_count({n}) = {got!r}, but a grid of {n} per edge has {expected} "
            "particles",
            cause=count_cause(got, n),
        )


def count_cause(got: object, n: int) -> str:
    """The cause of a wrong particle count ``got`` for ``n`` per edge: the hint of the mistake
    it is, where it is one of the usual ones."""
    causes = {  # where two coincide (n = 3: 3n = n²) the later one is said
        3 * n: "n + n + n, a sum of the edges: the cube has n·n·n particles",
        20**3: "a result that holds for the default N only (N³ for every n)",
        n: "counting one edge (n) instead of the whole cube (n³)",
        n**2: "counting one layer (n²) instead of the whole cube (n³)",
        (n + 1) ** 3: "n + 1 particles per edge: the grid has n per edge, indices 0 .. n - 1",
        (n - 1) ** 3: "n - 1 particles per edge: the grid has n per edge, indices 0 .. n - 1",
    }
    usual = "the grid has n particles along each of its three axes: n·n·n in all"
    return causes.get(got, usual) if isinstance(got, (int, float, np.number)) else usual


ACCEPTED_SCHEMES = ("position verlet", "symplectic euler")
SCHEME_HINTS = {
    "explicit euler": "explicit Euler moves with the velocity of the previous step; the kernel "
    "first adds dt·a to v and then moves with the new v. Put v = (cur - old)/dt + dt·a into "
    "new = cur + dt·v and compare with eq. (1.3)",
    "velocity verlet": "velocity Verlet evaluates the acceleration twice per step and "
    "stores a velocity; the kernel has only positions (old, current, new). Put v into "
    "the last line and compare with eq. (1.3)",
    "runge-kutta 4": "Runge-Kutta 4 evaluates the acceleration four times per step; the "
    "kernel does it once",
}


@pytest.mark.points(2)
def test_kernel_is_position_verlet(task1):
    """integration_scheme() names the scheme msd_kernel really is (eq. 1.3)."""
    answer = str(task1.integration_scheme()).strip().lower()
    expect(
        answer in ACCEPTED_SCHEMES,
        saw=f"you named the kernel's scheme {answer!r}",
        cause=SCHEME_HINTS.get(
            answer, "an answer outside SCHEMES; substitute v into new = cur + dt·v"
        ),
    )


def template_kernel(old: np.ndarray, current: np.ndarray, dt: float, a: np.ndarray) -> np.ndarray:
    """The template's three lines (floor left out)."""
    v = (current - old) / dt
    v = v + dt * a
    return current + dt * v


def floor_clamped(positions: np.ndarray) -> np.ndarray:
    """``positions`` with the template's floor y >= 0 applied."""
    clamped = positions.copy()
    clamped[..., 1] = np.maximum(clamped[..., 1], 0.0)
    return clamped


@pytest.mark.points(2)
def test_verlet_step_is_the_kernel(task1):
    """verlet_step (eq. 1.3) gives the same new positions as the template's kernel."""
    rng = np.random.default_rng(1)
    a = np.array([0.01, -0.001, 0.002])
    cases = (((4, 3, 5, 3), DT, 5.0), ((7, 3), 0.37, 5.0), ((6, 3), DT, 0.0))
    for shape, dt, lift in cases:  # dt is an argument too; lift 0: some cross the floor
        current = rng.uniform(-1.0, 1.0, shape) + np.array([0.0, lift, 0.0])
        old = current - 0.05 * rng.standard_normal(shape)
        expected = template_kernel(old, current, dt, a)
        got = as_array(task1.verlet_step(old.copy(), current.copy(), dt, tuple(a)), "verlet_step")
        mistake = matching_variant(
            got,
            {
                "the acceleration is missing (a·dt² was left out)": 2 * current - old,
                "a·dt instead of a·dt²": 2 * current - old + a * dt,
                "½·a·dt², the exact free fall of one step, instead of the kernel's a·dt²": (
                    2 * current - old + 0.5 * a * dt**2
                ),
                "x(t - dt) added instead of subtracted": 2 * current + old + a * dt**2,
                **{
                    f"your DT = {constant:g} instead of the dt argument": (
                        2 * current - old + a * constant**2
                    )
                    for constant in filter(None, [oracles.task_constant(task1, "DT")])
                },
                "the floor clamp y = max(y, 0) copied from the template's kernel: task 1's "
                "verlet_step leaves the floor out": floor_clamped(expected),
            },
        )
        expect(
            got.shape == expected.shape and relative_error(got, expected) < 1e-12,
            saw=f"for positions of shape {shape} and dt = {dt} verlet_step differs from the "
            f"kernel's new positions by up to {num(np.max(np.abs(got - expected)))} (positions ~1)",
            cause=mistake
            or "eq. (1.3) is x(t+dt) = 2 x(t) - x(t-dt) + a dt², with current = "
            "x(t) and old = x(t-dt)",
        )


@pytest.mark.points(2)
def test_height_after_as_template(task1, own_numbers):
    """height_after(n) is the height the running template reaches after n steps (from the
    student's own bottom layer and acceleration where each student has their own numbers)."""
    bottom, g = own_numbers.bottom, own_numbers.gravity
    first = int(floor_step(bottom, g)[0])
    heights = free_fall_heights(bottom, DT, g, first + 60)
    for n in (0, 1, 2, 10, 100, first - 1, first + 50):
        call = f"height_after({n}, {bottom}, {DT}, {g})"
        got = float(returned(task1.height_after(n, bottom, DT, g), call))
        parabola = bottom + 0.5 * g * (n * DT) ** 2
        cause = (
            Recognised(
                "that is the exact free fall y0 + ½ g t²; the template moves by g dt² in its "
                "first step, 2 g dt² in the second, ...: y0 + g dt² n(n+1)/2"
            )
            if n > 0 and np.isclose(got, parabola, rtol=0, atol=1e-12)
            else "the template's recurrence: each step adds g·dt² to the distance moved per "
            "step, so after n steps y = y0 + g dt² (1 + 2 + ... + n)"
        )
        shown, running = apart(got, heights[n], 6)
        expect(
            abs(got - heights[n]) <= 1e-9,
            saw=f"height_after({n}, {bottom}, {DT}, {g}) = {shown}, but the running template "
            f"is at y = {running} after {n} steps (y0 = {bottom}, dt = {DT}, g = {g})",
            cause=cause,
        )


@cached  # the same for every submission: computed once per grading run
def floor_step(bottom: float, g: float) -> np.ndarray:
    """The step in which the running template's bottom layer (y0 = ``bottom``, acceleration
    ``g``) first reaches the floor, and its height one step before (an array: the cache
    keeps arrays and numbers)."""
    start = oracles.template_positions((3, 2, 3), 0.1, (-1.0, bottom, -1.0))
    steps = int(2 * np.sqrt(2 * bottom / abs(g)) / DT) + 10  # twice the parabola's
    frames = oracles.template_run(start, steps, acceleration=(0.0, g, 0.0))
    on_floor = np.flatnonzero(frames[:, :, 0, :, 1].min(axis=(1, 2)) <= 0.0)
    first = int(on_floor[0])
    return np.array([first, frames[first - 1, :, 0, :, 1].min()])


def floor_answer(task1, *arguments: float) -> object:
    """The student's steps_to_floor(*arguments); where it fails while their height_after
    returns nothing, a failure naming that mistake (it is what steps_to_floor stumbled on)."""
    try:
        return task1.steps_to_floor(*arguments)
    except Exception as error:
        try:
            height = task1.height_after(1, 1.0, DT, -0.0015)
        except Exception:
            raise error from None
        if height is not None:
            raise
        call = f"steps_to_floor({', '.join(map(str, arguments))})"
        expect(False, saw=f"{call} fails ({type(error).__name__})", cause=no_return("height_after"))


def not_own_numbers(task1, own_numbers, got) -> Recognised | None:
    """The mistake of numbers in task1.py that are not the student's own (another student's
    copy of the template, or edited), where ``got`` is the floor step of those numbers."""
    try:
        bottom, g = float(task1.ORIGIN[1]), float(task1.GRAVITY[1])
    except Exception:  # no such constants: no such cause
        return None
    own = (own_numbers.bottom, own_numbers.gravity)
    if (
        np.allclose((bottom, g), own)
        or not (bottom > 0 > g)
        or got != int(floor_step(bottom, g)[0])
    ):
        return None
    differ = [
        f"{name} = {theirs:g} where your copy of the course has {mine:g}"
        for name, theirs, mine in (("ORIGIN[1]", bottom, own[0]), ("GRAVITY[1]", g, own[1]))
        if not np.isclose(theirs, mine)
    ]
    return Recognised(
        f"the numbers in your task1.py are not the ones given to you ({'; '.join(differ)}): "
        "the answer is about your own numbers, put them back"
    )


@pytest.mark.points(2)
def test_steps_to_floor_as_template(task1, own_numbers):
    """steps_to_floor() is the step in which the running template's floor first catches the
    bottom layer (of the student's own template where each student has their own numbers)."""
    bottom, g = own_numbers.bottom, own_numbers.gravity
    first, height = floor_step(bottom, g)
    first = int(first)
    for got, call in (
        (returned(floor_answer(task1), "steps_to_floor()"), "steps_to_floor()"),
        (floor_answer(task1, bottom, DT, g), f"steps_to_floor({bottom}, {DT}, {g})"),
    ):
        expect(
            got == first,
            saw=f"{call} = {got!r}, but the running template's bottom layer (y0 = {bottom}) "
            f"first reaches the floor in step {first} (its height after step {first - 1} is "
            f"{num(height)})",
            cause=(not_own_numbers(task1, own_numbers, got) if call.endswith("()") else None)
            or floor_step_mistake(got, first, bottom, g),
        )


def floor_step_mistake(got: object, first: int, bottom: float, g: float) -> str:
    """The cause of a wrong floor step: one step off, or the exact parabola's step (both
    recognised), else the usual cause."""
    if got in (first - 1, first + 1):
        return Recognised(
            f"one step {'early' if got < first else 'late'}: the answer is the first n whose "
            "height y0 + g dt² n(n+1)/2 is <= 0"
        )
    parabola = np.sqrt(2 * bottom / abs(g)) / DT  # ½ |g| t² = y0 at t = n dt
    if got in (math.floor(parabola), math.ceil(parabola)):
        return Recognised(
            "the exact parabola ½ g t² instead of the template's y0 + g dt² n(n+1)/2 (solve "
            "n(n+1)/2 · |g| dt² >= y0 for the smallest integer n)"
        )
    return (
        "the template's heights are y0 + g dt² n(n+1)/2 (see height_after): the answer is "
        "the smallest integer n with n(n+1)/2 · |g| dt² >= y0"
    )
