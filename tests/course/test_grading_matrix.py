"""Every way of grading gives the reference answers full marks and the templates nothing.

The matrix: each isolation mode (namespace, process) × each hand-in form (a folder, a zip,
a git repository, the Gradescope autograder run as Gradescope runs it) × the reference
answers (solutions/) and the templates (assignments/), with the course's own numbers off
and on. The checks are the course's own, hidden ones included, so every task's checks run
in the sandbox. Each (mode, numbers) is graded once, in one ``msdlab grade`` run over every
form and answer (a roster names them), and its rows are shared by the cells that read them.
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
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT, TASKS, own_numbers
from msdlab.instructor import sandbox
from msdlab.instructor.gradescope import ROOT_VARIABLE

MODES = ("namespace", "process")
FORMS = ("folder", "zip", "git")
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
def graded(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, bool], dict]:
    """``graded(mode, own)``: the grades file's rows by id (and ``"max"``) of one
    ``msdlab grade`` run over every form and answer, made once per (mode, own)."""
    runs: dict[tuple[str, bool], dict] = {}

    def rows(mode: str, own: bool) -> dict:
        usable(mode)
        if (mode, own) not in runs:
            root = tmp_path_factory.mktemp(f"{mode}-{'own' if own else 'course'}")
            root.chmod(0o755)  # as root, the namespace sandbox's user reads the copies
            checks = course(root / "course", own)
            lines = ["id,folder"]
            for form in FORMS:
                for answer in ANSWERS:
                    identifier = student(form, answer)
                    files = task_files(answer, identifier, own)
                    path = HAND_IN[form](root / "class" / identifier, files)
                    lines.append(f"{identifier},{path.relative_to(root)}")
            (root / "roster.csv").write_text("\n".join(lines) + "\n")
            out = root / "out" / "grades.csv"
            arguments = ["grade", "--roster", str(root / "roster.csv"), "--out", str(out)]
            arguments += ["--checks", str(checks), "--isolation", mode, "--jobs", "2"]
            status = main(arguments)
            with out.open(newline="", encoding="utf-8") as handle:
                table = {row["id"]: row for row in csv.DictReader(handle)}
            table["max"] = table.pop("(max points)")
            runs[mode, own] = {"status": status, "rows": table}
        return runs[mode, own]

    return rows


@pytest.mark.parametrize("own", NUMBERS, ids=NUMBERS.values())
@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("mode", MODES)
def test_the_reference_answers_get_full_marks(graded, mode: str, form: str, own: bool) -> None:
    run = graded(mode, own)
    row, possible = run["rows"][student(form, "reference")], run["rows"]["max"]
    assert run["status"] == 0
    assert row["fingerprint"], row["notes"]  # graded to the end
    assert int(possible["total"]) > 0
    for column in (*(f"task{task}" for task in TASKS), "total"):
        assert row[column] == possible[column], f"{column}: {row['notes']}"


@pytest.mark.parametrize("own", NUMBERS, ids=NUMBERS.values())
@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("mode", MODES)
def test_the_templates_get_nothing(graded, mode: str, form: str, own: bool) -> None:
    row = graded(mode, own)["rows"][student(form, "template")]
    assert row["fingerprint"], row["notes"]
    assert [row[f"task{task}"] for task in TASKS] == ["0"] * len(TASKS) and row["total"] == "0"


# ---------------------------------------------------------------- the Gradescope autograder


@pytest.fixture(scope="module")
def autograded(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str, str], dict]:
    """``autograded(mode, answer)``: results.json of the autograder zip (built for the
    sandbox ``mode`` with the course's checks) run on ``answer`` as Gradescope runs it."""
    roots: dict[str, Path] = {}
    results: dict[tuple[str, str], dict] = {}

    def run(mode: str, answer: str) -> dict:
        usable(mode)
        if mode not in roots:
            roots[mode] = autograder(tmp_path_factory.mktemp(f"gradescope-{mode}"), mode)
        if (mode, answer) not in results:
            results[mode, answer] = run_autograder(roots[mode], task_files(answer, "", False))
        return results[mode, answer]

    return run


def autograder(folder: Path, mode: str) -> Path:
    """The zip ``msdlab gradescope`` builds, unpacked where Gradescope puts it."""
    folder.chmod(0o755)
    out = folder / "autograder.zip"
    checks = PROJECT_ROOT / "tests" / "tasks"
    assert main(["gradescope", str(out), "--checks", str(checks), "--isolation", mode]) == 0
    root = folder / "autograder"
    with zipfile.ZipFile(out) as archive:
        archive.extractall(root / "source")
    shutil.copyfile(root / "source" / "run_autograder", root / "run_autograder")
    return root


def run_autograder(root: Path, files: dict[str, str]) -> dict:
    """Gradescope's steps for one submission: the upload's files in ``submission/``, its
    metadata beside it, ``run_autograder`` run from the root; the results it wrote."""
    shutil.rmtree(root / "submission", ignore_errors=True)
    shutil.rmtree(root / "results", ignore_errors=True)
    write_files(root / "submission", files)
    metadata = {"created_at": "2027-03-01T12:00:00.000000+00:00", "users": [{"sid": "s1"}]}
    (root / "submission_metadata.json").write_text(json.dumps(metadata))
    environment = dict(os.environ, PYTHON=sys.executable, **{ROOT_VARIABLE: str(root)})
    subprocess.run(["bash", str(root / "run_autograder")], cwd=root, env=environment,
                   check=True, timeout=600, capture_output=True)  # fmt: skip
    return json.loads((root / "results" / "results.json").read_text())


@pytest.mark.parametrize("mode", MODES)
def test_the_autograder_gives_the_reference_answers_full_marks(autograded, mode: str) -> None:
    results = autograded(mode, "reference")
    possible = sum(test["max_score"] for test in results["tests"])
    assert possible > 0 and results["score"] == possible, results["output"]
    assert {f"task{task}" for task in TASKS} == set(results["extra_data"]["tasks"])


@pytest.mark.parametrize("mode", MODES)
def test_the_autograder_gives_the_templates_nothing(autograded, mode: str) -> None:
    results = autograded(mode, "template")
    assert results["score"] == 0 and results["tests"]
    assert all(test["score"] == 0 for test in results["tests"])
