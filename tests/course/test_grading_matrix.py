"""Every way of grading gives the reference answers full marks and the templates nothing.

The matrix: each isolation mode (namespace, process) × each hand-in form (a folder, a zip,
a git repository, the Gradescope autograder run as Gradescope runs it) × the reference
answers (solutions/) and the templates (assignments/), with the course's own numbers off
and on. The checks are the course's own, hidden ones included, so every task's checks run
in the sandbox. The folder, zip and git forms of one (mode, numbers) are graded once, in
one ``msdlab grade`` run (a roster names them), the Gradescope form once per answer, and
every result is shared by the cells that read it.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
import zipfile
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT, TASKS, own_numbers
from msdlab.instructor.judging import sandbox
from msdlab.instructor.judging.gradescope import METADATA, ROOT_VARIABLE

MODES = ("namespace", "process")
FORMS = ("folder", "zip", "git", "gradescope")
NUMBERS = {False: "course numbers", True: "own numbers"}
ANSWERS = {"reference": PROJECT_ROOT / "solutions", "template": PROJECT_ROOT / "assignments"}
TASK_FILES = [f"task{task}.py" for task in TASKS]


def usable(mode: str) -> None:
    """Skip, with the reason, where sandboxes of isolation ``mode`` cannot start here."""
    problem = sandbox.isolation_problem(mode)
    if problem is not None:
        pytest.skip(f"the {mode} sandbox cannot start here: {problem}")


def student(form: str, answer: str) -> str:
    """The roster id of a cell's submission; with own numbers on, its numbers are its own."""
    return f"{form}-{answer}"


def task_files(answer: str, identifier: str, own: bool) -> dict[str, str]:
    """The task files of ``answer`` as the student ``identifier`` hands them in (with their
    own numbers where the course gives them)."""
    numbers = own_numbers.numbers(identifier if own else None)
    return {
        name: own_numbers.personalised(task, (ANSWERS[answer] / name).read_text(), numbers)
        for task, name in zip(TASKS, TASK_FILES)
    }


def write_files(folder: Path, files: dict[str, str]) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    return folder


def hand_in_folder(place: Path, files: dict[str, str]) -> Path:
    return write_files(place, files)


def hand_in_zip(place: Path, files: dict[str, str]) -> Path:
    """A zip of the release's folder: the task files inside ``assignments/``."""
    archive = place.with_suffix(".zip")
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as bundle:
        for name, text in files.items():
            bundle.writestr(f"assignments/{name}", text)
    return archive


def hand_in_repository(place: Path, files: dict[str, str]) -> Path:
    """A git repository whose one commit holds the task files (as GitHub Classroom clones)."""
    if shutil.which("git") is None:
        pytest.skip("the git form is built with git, which is not installed")
    write_files(place, files)
    moment = "2027-03-01T12:00:00+00:00"
    environment = dict(os.environ, GIT_AUTHOR_DATE=moment, GIT_COMMITTER_DATE=moment,
                       GIT_CONFIG_GLOBAL=os.devnull, GIT_CONFIG_NOSYSTEM="1")  # fmt: skip
    identity = ["-c", "user.name=A Student", "-c", "user.email=student@example.org"]
    for command in (["init", "-q"], ["add", "."], [*identity, "commit", "-q", "-m", "tasks"]):
        subprocess.run(["git", "-C", str(place), *command], env=environment, check=True)
    return place


HAND_IN: dict[str, Callable[[Path, dict[str, str]], Path]] = {
    "folder": hand_in_folder,
    "zip": hand_in_zip,
    "git": hand_in_repository,
}


def course(root: Path, own: bool) -> Path:
    """A course with the course's checks and its own-numbers switch; returns its checks."""
    checks = root / "tests" / "tasks"
    shutil.copytree(PROJECT_ROOT / "tests" / "tasks", checks,
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    (root / own_numbers.SETTINGS_FILE).write_text(json.dumps({"own_numbers": own}) + "\n")
    return checks


@pytest.fixture(scope="module")
def graded(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, bool, str, str], dict]:
    """``graded(mode, own, form, answer)``: the points of that cell by column (``task1`` ...
    ``total``) as (earned, possible), and its ``notes``. The folder, zip and git forms of one
    (mode, own) are graded by one ``msdlab grade`` run, Gradescope's form by the autograder
    zip run for each answer; each is made once and shared."""
    runs: dict[tuple, dict] = {}

    def cell(mode: str, own: bool, form: str, answer: str) -> dict:
        usable(mode)
        key = (mode, own, "gradescope", answer) if form == "gradescope" else (mode, own)
        if key not in runs:
            root = tmp_path_factory.mktemp(f"{mode}-{NUMBERS[own].split()[0]}-{form}")
            root.chmod(0o755)  # as root, the namespace sandbox's user reads the copies
            checks = course(root / "course", own)
            if form == "gradescope":
                runs[key] = {answer: autograded(root, checks, mode, own, answer)}
            else:
                runs[key] = grade_run(root, checks, mode, own)
        return runs[key][answer if form == "gradescope" else student(form, answer)]

    return cell


def grade_run(root: Path, checks: Path, mode: str, own: bool) -> dict[str, dict]:
    """``msdlab grade`` over the folder, zip and git forms of every answer (a roster names
    them): each one's cell, by id."""
    lines = ["id,folder"]
    for form in HAND_IN:
        for answer in ANSWERS:
            identifier = student(form, answer)
            path = HAND_IN[form](root / "class" / identifier, task_files(answer, identifier, own))
            lines.append(f"{identifier},{path.relative_to(root)}")
    (root / "roster.csv").write_text("\n".join(lines) + "\n")
    out = root / "out" / "grades.csv"
    arguments = ["grade", "--roster", str(root / "roster.csv"), "--out", str(out)]
    arguments += ["--checks", str(checks), "--isolation", mode, "--jobs", "2"]
    assert main(arguments) == 0
    with out.open(newline="", encoding="utf-8") as handle:
        table = {row["id"]: row for row in csv.DictReader(handle)}
    possible = table.pop("(max points)")
    columns = [*(f"task{task}" for task in TASKS), "total"]
    return {
        identifier: {
            **{c: (Fraction(row[c]), Fraction(possible[c])) for c in columns},
            "notes": row["notes"],
            "graded": bool(row["fingerprint"]),
        }
        for identifier, row in table.items()
    }


def autograded(root: Path, checks: Path, mode: str, own: bool, answer: str) -> dict:
    """The cell of ``answer`` handed in to the autograder zip ``msdlab gradescope`` builds
    for the sandbox ``mode`` (unpacked where Gradescope puts it), run as Gradescope runs it:
    the upload's files in ``submission/``, Gradescope's metadata beside it (the student's
    roster id as ``sid``), ``run_autograder`` from the root."""
    out = root / "autograder.zip"
    assert main(["gradescope", str(out), "--checks", str(checks), "--isolation", mode]) == 0
    tree = root / "autograder"
    with zipfile.ZipFile(out) as archive:
        archive.extractall(tree / "source")
    shutil.copyfile(tree / "source" / "run_autograder", tree / "run_autograder")
    identifier = student("gradescope", answer)
    write_files(tree / "submission", task_files(answer, identifier, own))
    user = {"name": "A Student", "email": "s@example.org", "sid": identifier}
    metadata = {"created_at": "2027-03-01T12:00:00.000000+00:00", "users": [user]}
    (tree / METADATA).write_text(json.dumps(metadata))
    environment = dict(os.environ, PYTHON=sys.executable, **{ROOT_VARIABLE: str(tree)})
    subprocess.run(["bash", str(tree / "run_autograder")], cwd=tree, env=environment,
                   check=True, timeout=600, capture_output=True)  # fmt: skip
    results = json.loads((tree / "results" / "results.json").read_text())
    tasks = results["extra_data"].get("tasks", {})
    possible = sum(test["max_score"] for test in results["tests"])
    return {
        **{f"task{t}": (Fraction(tasks.get(f"task{t}", {}).get("score", 0)),
                        Fraction(tasks.get(f"task{t}", {}).get("max_score", 0))) for t in TASKS},
        "total": (Fraction(results["score"]), Fraction(possible)),
        "notes": results["output"],
        "graded": bool(tasks),
    }  # fmt: skip


@pytest.mark.parametrize("own", NUMBERS, ids=NUMBERS.values())
@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("mode", MODES)
def test_the_reference_answers_get_full_marks(graded, mode: str, form: str, own: bool) -> None:
    cell = graded(mode, own, form, "reference")
    assert cell["graded"], cell["notes"]
    assert cell["total"][1] > 0
    for task in TASKS:
        earned, possible = cell[f"task{task}"]
        assert possible > 0 and earned == possible, f"task{task}: {cell['notes']}"
    assert cell["total"][0] == cell["total"][1]


@pytest.mark.parametrize("own", NUMBERS, ids=NUMBERS.values())
@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("mode", MODES)
def test_the_templates_get_nothing(graded, mode: str, form: str, own: bool) -> None:
    cell = graded(mode, own, form, "template")
    assert cell["graded"], cell["notes"]
    assert [cell[f"task{task}"][0] for task in TASKS] == [0] * len(TASKS)
    assert cell["total"][0] == 0 and cell["total"][1] > 0
