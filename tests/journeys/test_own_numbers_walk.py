"""A week with own numbers, walked as the instructor and one student walk it.

The instructor switches own numbers on in a clone of the course and releases alice's
bundle; alice, on the system's Python, follows the release README as written (a virtual
environment first), reads her own numbers in her task file, her notebook and the header
of ``msdlab check``, runs the task 1 notebook on the kernel it names, and finishes her
work; the instructor grades her, and bob who handed in a copy of her task 1, locally
and through the Gradescope autograder zip. Each student is graded against their own
numbers on both paths, and only the instructor reads whose numbers bob's are.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from harness import ROOT, Session, Typed, quick_start

from msdlab.course import own_numbers
from msdlab.instructor import templates
from msdlab.instructor.judging import sandbox
from msdlab.instructor.judging.gradescope import METADATA, ROOT_VARIABLE

pytestmark = [
    pytest.mark.timeout(1800),
    pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed"),
]

ALICE, BOB = "alice", "carol"  # ids whose numbers differ (tests/course/test_own_numbers.py)
ISOLATION = "" if sandbox.isolation_problem() is None else " --isolation process"


@pytest.fixture(scope="module")
def home(tmp_path_factory, shell) -> Path:
    """The instructor's folder: a clone ``msdlab/`` with own numbers on, alice's release."""
    home = tmp_path_factory.mktemp("own")
    assert shell(f"git clone -q {ROOT} msdlab", home).status == 0
    (home / "msdlab" / own_numbers.SETTINGS_FILE).write_text('{"own_numbers": true}\n')
    released = shell(f"msdlab release release/{ALICE} --course msdlab --student {ALICE}", home)
    assert released.status == 0, released
    return home


@pytest.fixture(scope="module")
def followed(bundle) -> tuple[Session, list[Typed]]:
    """Alice's terminal on the system's Python, after she typed the release README's
    Quick start there, and what each line printed."""
    student = Session()
    return student, [student.type(line, bundle) for line in quick_start(bundle / "README.md")]


@pytest.fixture(scope="module")
def student(followed) -> Session:
    return followed[0]


@pytest.fixture(scope="module")
def bundle(home) -> Path:
    return home / "release" / ALICE


def test_the_readme_works_as_written_on_the_systems_python(bundle, followed):
    lines, (student, typed) = quick_start(bundle / "README.md"), followed
    assert lines[0] == "python3 -m venv .venv && . .venv/bin/activate", lines
    assert all(done.status == 0 for done in typed[:-1]), typed
    assert student.venv == bundle / ".venv"
    assert "animation:" in typed[1].output, typed[1]
    check = typed[-1]
    assert check.status == 1 and "to do in assignments/" in check.output, check
    alice = own_numbers.numbers(ALICE)
    assert f"with your own numbers (student {ALICE})" in check.output, check
    assert f"y0 = ORIGIN[1] = {alice.bottom}" in check.output


def test_her_task_file_and_notebook_show_her_numbers(bundle):
    alice, shown = own_numbers.numbers(ALICE), own_numbers.shown(own_numbers.numbers(ALICE))
    task1 = (bundle / "assignments" / "task1.py").read_text()
    assert f"ORIGIN = (-1.0, {alice.bottom}, -1.0)" in task1
    assert f"(y0 = ORIGIN[1] = {alice.bottom}) the exact free fall" in task1
    assert f"would land at t = {shown['fall_time']}:" in task1
    notebook = json.loads((bundle / "notebooks" / "task1.ipynb").read_text())
    text = "\n".join(cell["source"] for cell in notebook["cells"])
    assert f"(0, {alice.gravity}, 0)" in text and "(0, -0.001, 0)" not in text
    assert notebook["metadata"]["msdlab"]["save_outputs"] is True  # her Jupyter keeps them


def test_the_notebook_runs_on_the_kernel_it_names_with_her_numbers(bundle, student):
    """The notebook's kernel is the environment's python3, named as ipykernel names it (no
    prompt on opening, no rename on saving); run there, the template lands her grid."""
    spec = json.loads((bundle / "notebooks" / "task1.ipynb").read_text())["metadata"]
    named = student.type(
        'python -c "from jupyter_client.kernelspec import KernelSpecManager as M; '
        "print(M().get_kernel_spec('python3').display_name)\"",
        bundle,
    )
    assert named.status == 0 and named.output.strip() == spec["kernelspec"]["display_name"]
    run = student.type(
        "python -c \"import nbformat, nbclient; nb = nbformat.read('task1.ipynb', 4); "
        "nbclient.NotebookClient(nb, kernel_name='python3', timeout=900, allow_errors=True)"
        ".execute(); print(''.join(o.get('text', '') for c in nb.cells if c.cell_type == "
        "'code' for o in c.outputs))\"",
        bundle / "notebooks",
        timeout=1200,
    )
    assert run.status == 0, run
    alice = own_numbers.numbers(ALICE)
    assert f"y from {alice.bottom:.2f}" in run.output, run.output
    landed = [line for line in run.output.splitlines() if "first touches the floor" in line]
    assert landed and landed[0].split()[-1] == str(expected_floor_step(alice)), landed


def expected_floor_step(own: own_numbers.Numbers) -> int:
    """The step in which a particle at rest at the bottom layer first reaches the floor."""
    height, speed, step = own.bottom, 0.0, 0
    while height > 0:
        speed += own.gravity * own_numbers.DT**2
        height += speed
        step += 1
    return step


@pytest.fixture(scope="module")
def finished(bundle, followed) -> Path:
    """Her answers in her bundle: the reference solutions, task 1's in her own template."""
    alice = own_numbers.numbers(ALICE)
    for path in sorted((ROOT / "solutions").glob("task*.py")):
        task = templates.task_number(path)
        text = own_numbers.personalised(task, path.read_text(), alice)
        (bundle / "assignments" / path.name).write_text(text)
    return bundle


def test_her_finished_work_gets_every_public_point(finished, student):
    check = student.type("msdlab check", finished)
    assert check.status == 0, check


@pytest.fixture(scope="module")
def handed_in(home, finished) -> Path:
    """``class/``: alice's work as she hands it in, and bob's: her task 1 copied."""
    room = home / "class"
    shutil.copytree(finished / "assignments", room / ALICE / "assignments",
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    shutil.copytree(room / ALICE / "assignments", room / BOB / "assignments")
    (room / BOB / "assignments" / own_numbers.STUDENT_FILE).write_text(json.dumps({"id": BOB}))
    (room / "roster.csv").write_text(f"id\n{ALICE}\n{BOB}\n")  # own numbers follow the roster
    return room


def test_grading_locally_uses_each_students_own_numbers(home, handed_in, shell):
    done = shell(
        "msdlab grade class/*/assignments --roster class/roster.csv --out grades.csv "
        "--feedback feedback/ --checks msdlab/tests/tasks" + ISOLATION,
        home,
    )
    assert done.status == 0, done
    rows = {row["id"]: row for row in csv.DictReader((home / "grades.csv").open())}
    assert rows[ALICE]["task1"] == rows["(max points)"]["task1"], rows[ALICE]
    assert float(rows[BOB]["task1"]) < float(rows[ALICE]["task1"]), rows[BOB]
    hint = f"are the own numbers of {ALICE}, not of {BOB}"
    assert hint in done.output
    assert hint in (home / "feedback" / "instructor" / f"{BOB}.md").read_text()
    assert ALICE not in (home / "feedback" / "students" / f"{BOB}.md").read_text()


def test_grading_through_the_gradescope_zip_uses_her_own_numbers(home, handed_in, shell):
    built = shell("msdlab gradescope autograder.zip --checks msdlab/tests/tasks", home)
    assert built.status == 0 and "with own numbers" in built.output, built
    root = home / "autograder"
    with zipfile.ZipFile(home / "autograder.zip") as archive:
        assert own_numbers.SETTINGS_FILE in archive.namelist()
        archive.extractall(root / "source")
    for student in (ALICE, BOB):
        shutil.rmtree(root / "submission", ignore_errors=True)
        shutil.copytree(handed_in / student / "assignments", root / "submission")
        users = {"users": [{"name": student.title(), "sid": student}]}
        (root / METADATA).write_text(json.dumps(users))
        environment = dict(os.environ, PYTHON=sys.executable, **{ROOT_VARIABLE: str(root)})
        subprocess.run(["bash", str(root / "source" / "run_autograder")], env=environment,
                       check=True, timeout=900, capture_output=True)  # fmt: skip
        results = json.loads((root / "results" / "results.json").read_text())
        task1 = results["extra_data"]["tasks"]["task1"]
        failed = [t["name"] for t in results["tests"] if t["status"] == "failed"]
        failed_in_task1 = [name for name in failed if name.startswith("Task 1:")]
        if student == ALICE:  # (task 1 is what own numbers change)
            assert task1["score"] == task1["max_score"] > 0, results["output"]
        else:  # her answers, his numbers
            assert failed_in_task1 == ["Task 1: steps_to_floor_as_template"], results["output"]
