"""`msdlab gradescope`: the zip's run_autograder, run on a copy of Gradescope's /autograder
tree, gives the solutions full marks, the templates 0 with what to do, and a hostile
submission a result with the reason."""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor.gradescope import ROOT_VARIABLE

HOSTILE = """
import os, sys
try:
    os.kill(os.getppid(), 9)  # the process that judges it
finally:
    sys.exit(0)
"""


@pytest.fixture(scope="module")
def autograder(tmp_path_factory: pytest.TempPathFactory, task1_checks: Path) -> Path:
    """The zip built by the command and unpacked where Gradescope puts it."""
    out = tmp_path_factory.mktemp("build") / "autograder.zip"
    options = ["--checks", str(task1_checks), "--call-timeout", "10"]
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


def run_autograder(root: Path, files: dict[str, str], subfolder: str = "") -> dict:
    """Put ``files`` in the submission folder, run the script as Gradescope would, read results."""
    shutil.rmtree(root / "submission", ignore_errors=True)
    shutil.rmtree(root / "results", ignore_errors=True)
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
    assert all(test["output"].startswith("to do: ") for test in results["tests"])
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
