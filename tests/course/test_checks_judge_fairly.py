"""The checks are fair: correct code written differently gets full marks, and the mistakes
students really make lose points with a message that names the cause."""

from __future__ import annotations

import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import pytest

from msdlab.course import PROJECT_ROOT
from msdlab.course.report import CheckReport, CheckResult

CHECKS = PROJECT_ROOT / "tests" / "tasks"
SOLUTIONS = PROJECT_ROOT / "solutions"
ALTERNATIVES = Path(__file__).parent / "alternatives"


@dataclass(frozen=True)
class Mistake:
    """A typical mistake: a change to a reference solution and what a check must say about it."""

    name: str
    task: int
    old: str
    new: str
    failing: dict[str, str]  # check name -> words its message must contain


MISTAKES = [
    Mistake(
        "exact parabola",
        1,
        "return y0 + g * dt**2 * steps * (steps + 1) / 2",
        "return y0 + 0.5 * g * (steps * dt) ** 2",
        {"height_after_as_template": "exact free fall"},
    ),
    Mistake(
        "rest length one",
        2,
        "(spacing - length) * direction",
        "(1.0 - length) * direction",
        {
            "grid_at_rest_feels_no_force": "pre-stressed",
            "matches_equations_on_a_deformed_grid": "rest length 1 in world units",
        },
    ),
    Mistake(
        "wrong sign",
        2,
        "(spacing - length) * direction",
        "(length - spacing) * direction",
        {
            "stretched_pulls_compressed_pushes": "the sign",
            "matches_equations_on_a_deformed_grid": "a stretched spring pushes",
            "energy_is_conserved_in_a_verlet_run": "total energy grew",
        },
    ),
    Mistake(
        "np.roll borders",
        2,
        "    a = np.zeros_like(x)\n    for axis in range(3):\n",
        "    a = np.zeros_like(x)\n"
        "    for axis in range(3):\n"
        "        for shift in (1, -1):\n"
        "            d = x - np.roll(x, shift, axis=axis)\n"
        "            length = np.linalg.norm(d, axis=-1, keepdims=True)\n"
        "            a += stiffness * (spacing - length) * d / np.where(length > 0, length, 1)\n"
        "    return a\n"
        "    for axis in range(3):\n",
        {
            "matches_equations_on_a_deformed_grid": "np.roll",
            "grid_at_rest_feels_no_force": "pre-stressed",
        },
    ),
    Mistake(
        "no reaction",
        2,
        "        a[second] -= f  # the equal and opposite force on j\n",
        "",
        {
            "forces_are_equal_and_opposite": "net acceleration",
            "matches_equations_on_a_deformed_grid": "only one end",
        },
    ),
    Mistake(
        "force along the grid axis",
        2,
        "direction = np.divide(d, length, out=np.zeros_like(d), where=length > 0)",
        "direction = np.sign(d[..., axis : axis + 1]) * np.eye(3)[axis]",
        {
            "rotating_the_grid_rotates_the_forces": "depends on how the body is oriented",
            "forces_are_equal_and_opposite": "net torque",
        },
    ),
    Mistake(
        "fancy-index accumulation",
        3,
        "    for axis in range(3):\n        a[:, axis] = np.bincount(",
        "    a[i] += f\n    a[j] -= f\n    return a\n    for axis in range(3):\n"
        "        a[:, axis] = np.bincount(",
        {"spring_acceleration_matches_equations": "repeated indices"},
    ),
    Mistake(
        "left-handed rotation",
        3,
        "np.sin(theta) * cross",
        "np.sin(theta) * cross.T",
        {"rotation_matrix_right_handed": "transpose"},
    ),
    Mistake(
        "rotation about the origin",
        3,
        "return ((points - centroid) @ rotation.T + centroid).reshape(positions.shape)",
        "return (points @ rotation.T).reshape(positions.shape)",
        {"rotate_layout_turns_about_centroid": "origin instead of the centroid"},
    ),
    Mistake(
        "springs listed both ways",
        4,
        "if tuple(offset) <= (0, 0, 0):",
        "if not any(offset):",
        {"grid_springs_each_pair_once": "listed twice"},
    ),
    Mistake(
        "rest lengths in grid units",
        4,
        "spacing * np.sqrt(np.sum(offset**2))",
        "np.sqrt(np.sum(offset**2))",
        {"rest_lengths_unstressed": "pre-stressed"},
    ),
    Mistake(
        "damping on the acceleration",
        5,
        "new = (2.0 - lam) * current - (1.0 - lam) * old + acceleration * dt**2",
        "new = 2.0 * current - old + (1.0 - lam) * acceleration * dt**2",
        {
            "one_step_is_equation_1_4": "damping applied to the acceleration",
            "damping_acts_on_velocity_only": "continues at",
        },
    ),
    Mistake(
        "damping out of range accepted",
        5,
        "if not 0.0 <= lam < 1.0:",
        "if lam > 10:",
        {"damping_outside_0_to_1_is_refused": "was accepted"},
    ),
    Mistake(
        "explicit Euler",
        5,
        "return new, (new - current) / dt",
        "return x + dt * v, v + dt * acceleration",
        {
            "one_step_is_equation_1_4": "explicit Euler",
            "predicted_stability_limit": "explicit Euler",
        },
    ),
    Mistake(
        "old velocity returned",
        5,
        "return new, (new - current) / dt",
        "return new, v",
        {
            "one_step_is_equation_1_4": "returning the old velocity",
            "no_damping_reproduces_the_template": "leaves the template's trajectory",
        },
    ),
]


def run_checks(folder: Path, marker: str, report: Path) -> CheckReport:
    single_thread = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            str(CHECKS),
            f"--impl={folder}",
            f"--msdlab-report={report}",
            "-m",
            marker,
            "-q",
            "--tb=no",
            "-p",
            "no:cacheprovider",
            "-p",
            "no:nbval",
        ],
        cwd=PROJECT_ROOT,
        env={**os.environ, **single_thread},  # two runs at a time on two cores
        capture_output=True,
        check=False,
    )
    return CheckReport.read(report)


@pytest.fixture(scope="module")
def mistake_reports(tmp_path_factory) -> dict[str, list[CheckResult]]:
    """The public checks of each mistake's task, run on the changed solution.

    Mistakes of different tasks share a folder (one run checks up to five of
    them); two runs go at a time.
    """
    rounds: list[dict[int, Mistake]] = []
    for mistake in MISTAKES:
        free = next((r for r in rounds if mistake.task not in r), None)
        if free is None:
            free = {}
            rounds.append(free)
        free[mistake.task] = mistake
    jobs = []
    for mistakes in rounds:
        folder = tmp_path_factory.mktemp("mistakes")
        for task, mistake in mistakes.items():
            source = (SOLUTIONS / f"task{task}.py").read_text()
            assert mistake.old in source, f"{mistake.name}: the solution changed"
            (folder / f"task{task}.py").write_text(source.replace(mistake.old, mistake.new))
        tasks = " or ".join(f"task{task}" for task in mistakes)
        jobs.append((folder, f"({tasks}) and not hidden", folder / "report.json"))
    with ThreadPoolExecutor(max_workers=2) as pool:
        reports = list(pool.map(lambda job: run_checks(*job), jobs))
    return {
        mistake.name: [check for check in report.checks if check.task == task]
        for mistakes, report in zip(rounds, reports)
        for task, mistake in mistakes.items()
    }


@pytest.mark.parametrize("mistake", MISTAKES, ids=[m.name for m in MISTAKES])
def test_mistake_loses_points_with_the_right_message(mistake, mistake_reports):
    results = {check.name: check for check in mistake_reports[mistake.name]}
    for name, words in mistake.failing.items():
        check = results[name]
        assert check.outcome == "failed", f"{name} did not catch '{mistake.name}'"
        assert words in check.message, f"{name} says: {check.message}"


def test_correct_code_written_differently_gets_full_marks(tmp_path):
    """Loops instead of arrays, np.add.at, springs stored (j, i), eq. (1.4) rearranged."""
    markers = "task1 or task2 or task3 or task4 or task5"
    report = run_checks(ALTERNATIVES, markers, tmp_path / "report.json")
    lost = [f"{c.name}: {c.exception} {c.message}" for c in report.checks if not c.passed]
    assert not lost, "\n".join(lost)
    assert report.tasks() == [1, 2, 3, 4, 5] and report.earned == report.points
