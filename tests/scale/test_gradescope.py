"""`msdlab gradescope`: the zip's run_autograder, run on a copy of Gradescope's /autograder
tree, gives the solutions full marks, the templates 0 with what to do, and a hostile
submission a result with the reason."""

from __future__ import annotations

import json
import os
import re
import shutil
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT, own_numbers
from msdlab.instructor.judging.gradescope import METADATA, ROOT_VARIABLE

HOSTILE = """
import os, sys
try:
    os.kill(os.getppid(), 9)  # the process that judges it
finally:
    sys.exit(0)
"""


def unpacked(tmp_path_factory: pytest.TempPathFactory, checks: Path) -> Path:
    """The zip built by the command for ``checks`` and unpacked where Gradescope puts it."""
    out = tmp_path_factory.mktemp("build") / "autograder.zip"
    options = ["--checks", str(checks), "--call-timeout", "10"]
    assert main(["gradescope", str(out), *options]) == 0
    root = tmp_path_factory.mktemp("autograder")
    with zipfile.ZipFile(out) as archive:
        archive.extractall(root / "source")
        modes = {info.filename: info.external_attr >> 16 for info in archive.infolist()}
    for script in ("setup.sh", "run_autograder"):
        assert modes[script] & stat.S_IXUSR, f"{script} is not executable in the zip"
    assert (root / "source" / "msdlab" / "pyproject.toml").is_file()
    assert (root / "source" / "checks" / "test_task1_hidden.py").is_file()
    subprocess.run(["bash", "-n", str(root / "source" / "setup.sh")], check=True)
    shutil.copyfile(root / "source" / "run_autograder", root / "run_autograder")
    return root


@pytest.fixture(scope="module")
def autograder(tmp_path_factory: pytest.TempPathFactory, task1_checks: Path) -> Path:
    """The zip of task 1's checks, unpacked where Gradescope puts it."""
    return unpacked(tmp_path_factory, task1_checks)


@pytest.fixture(scope="module")
def own_autograder(tmp_path_factory: pytest.TempPathFactory, task1_checks: Path) -> Path:
    """The same for a course that gives each student their own numbers (its course.json)."""
    course = tmp_path_factory.mktemp("course")
    (course / own_numbers.SETTINGS_FILE).write_text('{"own_numbers": true}')
    checks = shutil.copytree(task1_checks, course / "tests" / "tasks")
    root = unpacked(tmp_path_factory, checks)
    assert own_numbers.enabled(root / "source")
    return root


def run_autograder(
    root: Path, files: dict[str, str], subfolder: str = "", metadata: dict | None = None
) -> dict:
    """Put ``files`` in the submission folder (and Gradescope's ``metadata`` beside it), run
    the script as Gradescope would, read results."""
    shutil.rmtree(root / "submission", ignore_errors=True)
    shutil.rmtree(root / "results", ignore_errors=True)
    (root / METADATA).unlink(missing_ok=True)
    if metadata is not None:
        (root / METADATA).write_text(json.dumps(metadata))
    folder = root / "submission" / subfolder
    folder.mkdir(parents=True)
    for name, text in files.items():
        (folder / name).write_text(text)
    environment = dict(os.environ, PYTHON=sys.executable, **{ROOT_VARIABLE: str(root)})
    subprocess.run(["bash", str(root / "run_autograder")], cwd=root, env=environment,
                   check=True, timeout=300, capture_output=True)  # fmt: skip
    return json.loads((root / "results" / "results.json").read_text())


def task_files(folder: Path) -> dict[str, str]:
    return {path.name: path.read_text() for path in folder.glob("task*.py")}


def test_solutions_get_full_marks_with_hidden_checks_after_publication(autograder: Path) -> None:
    results = run_autograder(autograder, task_files(PROJECT_ROOT / "solutions"))
    tests = results["tests"]
    possible = sum(test["max_score"] for test in tests)
    assert possible > 0 and results["score"] == possible
    assert all(test["status"] == "passed" and test["score"] == test["max_score"] for test in tests)
    visibility = {test["visibility"] for test in tests}
    assert visibility == {"visible", "after_published"}
    assert results["extra_data"]["tasks"]["task1"] == {"score": possible, "max_score": possible}
    assert f"task1: {possible}/{possible}" in results["output"]


def test_templates_in_assignments_get_zero_and_say_what_to_do(autograder: Path) -> None:
    results = run_autograder(autograder, task_files(PROJECT_ROOT / "assignments"), "assignments")
    assert results["score"] == 0
    assert results["tests"] and all(test["score"] == 0 for test in results["tests"])
    public = [test for test in results["tests"] if test["visibility"] == "visible"]
    for test in public:  # the file and the function to write, and what
        assert re.match(r"to do in task1\.py, \w+: \S", test["output"]), test["output"]
        assert "\n" not in test["output"]  # said once
    hidden = [test for test in results["tests"] if test["visibility"] != "visible"]
    assert hidden and all(test["output"] == "" for test in hidden)  # points only, as locally
    assert {t["output"].split(",")[1].split(":")[0].strip() for t in public} >= {
        "particle_count",
        "verlet_step",
        "steps_to_floor",
    }
    assert "task1: not attempted" in results["output"]


def test_a_hostile_submission_gets_a_result_with_the_reason(autograder: Path) -> None:
    files = task_files(PROJECT_ROOT / "assignments")
    files["task1.py"] = task_files(PROJECT_ROOT / "solutions")["task1.py"] + HOSTILE
    results = run_autograder(autograder, files)
    assert results["score"] == 0
    assert results["tests"] and all(test["score"] == 0 for test in results["tests"])
    reason = results["output"].lower()
    assert "could not" in reason or "task1:" in reason, results["output"]


def test_the_hidden_checks_can_stay_hidden(tmp_path: Path, task1_checks: Path) -> None:
    out = tmp_path / "autograder.zip"
    options = ["--checks", str(task1_checks), "--hidden-visibility", "hidden"]
    assert main(["gradescope", str(out), *options]) == 0
    with zipfile.ZipFile(out) as archive:
        assert json.loads(archive.read("msdlab-autograder.json"))["hidden_visibility"] == "hidden"
    assert main(["gradescope", str(tmp_path / "autograder.tar"), *options]) == 2


def own_task1(student: str) -> dict[str, str]:
    """The reference answer of task 1 in ``student``'s own release."""
    own = own_numbers.numbers(student)
    solution = (PROJECT_ROOT / "solutions" / "task1.py").read_text()
    return {"task1.py": own_numbers.personalised(1, solution, own)}


def gradescope_user(sid: str) -> dict:
    return {"users": [{"name": "A Student", "email": f"{sid}@example.org", "sid": sid}]}


def test_with_own_numbers_each_student_is_graded_against_their_own(own_autograder) -> None:
    """The zip carries course.json: correct alice gets full marks, with the id from
    Gradescope's roster; her answers under carol's id miss the floor step."""
    results = run_autograder(own_autograder, own_task1("alice"), metadata=gradescope_user("alice"))
    possible = sum(test["max_score"] for test in results["tests"])
    assert possible > 0 and results["score"] == possible, results["output"]
    handed = run_autograder(own_autograder, own_task1("alice"), metadata=gradescope_user("carol"))
    failed = [test["name"] for test in handed["tests"] if test["status"] == "failed"]
    assert failed == ["Task 1: steps_to_floor_as_template"], handed["output"]


def test_with_own_numbers_and_no_roster_id_the_student_is_told_why(own_autograder) -> None:
    results = run_autograder(own_autograder, own_task1("alice"), metadata={"users": [{}]})
    assert results["score"] == 0
    assert "no sid of yours in Gradescope's submission metadata" in results["output"]


def test_the_zip_is_not_written_into_the_course_folder(task1_checks: Path) -> None:
    inside = PROJECT_ROOT / "autograder-test.zip"
    assert main(["gradescope", str(inside), "--checks", str(task1_checks)]) == 2
    assert not inside.exists()
