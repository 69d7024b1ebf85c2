"""The instructor's journey: a clone of the course in a folder named ``msdlab``, a class of
five beside it in ``class/``, graded from the folder that holds both, then one student who
handed in again graded from inside the clone; what the instructor reads in the grades
file, the feedback files and the summary."""

from __future__ import annotations

import csv
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest
from browser import CHROMIUM, jupyterlab_server, launch, run_notebook, wait_until

from msdlab.course import PROJECT_ROOT
from msdlab.instructor.judging import sandbox

NO_EQUAL_AND_OPPOSITE = ("a[second] -= f", "a[second] += f")  # task 2: j feels no force
# grading as it normally runs: each submission in its bubblewrap sandbox, where there is one
ISOLATION = "" if sandbox.isolation_problem() is None else " --isolation process"

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def hand_in(student: Path, source: Path, change: tuple[str, str] | None = None) -> Path:
    """``student/assignments``: the task files of ``source``, with one text ``change``."""
    assignments = student / "assignments"
    shutil.copytree(source, assignments, ignore=shutil.ignore_patterns("__pycache__"))
    if change is not None:
        (path,) = [p for p in assignments.glob("task*.py") if change[0] in p.read_text()]
        path.write_text(path.read_text().replace(*change))
    return assignments


@pytest.fixture(scope="module")
def home(tmp_path_factory, shell) -> Path:
    """The instructor's folder: the clone ``msdlab/`` and the ``class/`` of five, graded."""
    home = tmp_path_factory.mktemp("term")
    cloned = shell(f"git clone -q {PROJECT_ROOT} msdlab", home)
    assert cloned.status == 0, cloned.output
    course, room = home / "msdlab", home / "class"
    hand_in(room / "alice", course / "solutions")
    hand_in(room / "bob", course / "assignments")  # the templates as released: nothing done
    hand_in(room / "carol", course / "solutions", NO_EQUAL_AND_OPPOSITE)
    dave = hand_in(room / "dave", course / "solutions")
    (dave / "task3.py").write_text((dave / "task3.py").read_text() + "\ndef unfinished(:\n")
    with zipfile.ZipFile(room / "erin.zip", "w") as bundle:
        for path in sorted((course / "solutions").glob("task*.py")):
            bundle.write(path, f"erin/{path.name}")
    return home


@pytest.fixture(scope="module")
def graded(home: Path, shell) -> str:
    """What the class's grading, typed in the folder holding the clone, printed."""
    done = shell(
        "msdlab grade class/*/assignments class/erin.zip --out grades.csv --feedback feedback/"
        + ISOLATION,
        home,
    )
    assert done.status == 0, done.output  # every submission graded
    return done.output


def grades(home: Path) -> dict[str, dict[str, str]]:
    return {row["id"]: row for row in csv.DictReader((home / "grades.csv").open())}


def test_the_class_is_graded_from_the_folder_holding_the_clone(home, graded):
    rows = grades(home)
    best = rows["(max points)"]
    assert list(rows) == ["(max points)", "alice", "bob", "carol", "dave", "erin"]
    assert rows["alice"]["total"] == rows["erin"]["total"] == best["total"] != "0", graded
    assert rows["bob"]["total"] == "0" and "task2: not attempted" in rows["bob"]["notes"]
    carol, dave = rows["carol"], rows["dave"]
    assert 0 < int(carol["task2"]) < int(best["task2"]) and carol["task1"] == best["task1"]
    assert dave["task3"] == "0" and "task3: syntax error" in dave["notes"]
    assert dave["task2"] == best["task2"] and dave["task5"] == best["task5"]
    assert "grader error" not in graded and "NOT GRADED" not in graded


def test_each_student_reads_what_went_wrong(home, graded):
    students = home / "feedback" / "students"
    names = {path.name for path in students.iterdir()}
    assert names == {f"{name}.md" for name in ("alice", "bob", "carol", "dave", "erin")}
    total = grades(home)["(max points)"]["total"]
    assert f"**{total} of {total} points**" in (students / "alice.md").read_text()
    assert "Not attempted yet" in (students / "bob.md").read_text()
    carol = (students / "carol.md").read_text()
    assert "## Task 1: " in carol and "passed" in carol and ": 0 of " in carol.split("## Task 2")[1]
    assert "SyntaxError" in (students / "dave.md").read_text().split("## Task 3")[1]
    summary = (home / "feedback" / "summary.md").read_text()
    assert "5 of 5 submissions graded." in summary and "Checks failed most often" in summary


def test_one_student_regraded_from_inside_the_clone_keeps_the_class(home, graded, shell):
    before = grades(home)
    carol = home / "class" / "carol" / "assignments" / "task2.py"
    carol.write_text(carol.read_text().replace(*reversed(NO_EQUAL_AND_OPPOSITE)))
    done = shell(
        "msdlab grade ../class/carol/assignments --out ../grades.csv --feedback ../feedback/"
        + ISOLATION,
        home / "msdlab",
    )
    assert done.status == 0 and "4 rows of earlier runs kept" in done.output, done.output
    after = grades(home)
    assert after["carol"]["total"] == after["(max points)"]["total"]
    assert {k: v for k, v in after.items() if k != "carol"} == {
        k: v for k, v in before.items() if k != "carol"
    }
    summary = (home / "feedback" / "summary.md").read_text()
    totals = [int(after[name]["total"]) for name in ("alice", "bob", "carol", "dave", "erin")]
    assert "5 of 5 submissions graded." in summary
    assert f"| total | {after['(max points)']['total']} | {sum(totals) / 5:.1f} |" in summary


def test_a_notebook_run_and_saved_in_the_clone_leaves_git_clean(home):
    """The instructor opens a task's notebook in the clone with JupyterLab, runs it, saves
    it: the page shows the outputs, and git shows no change."""
    pytest.importorskip("playwright", reason="needs playwright (pip install -e '.[test]')")
    if CHROMIUM is None:
        pytest.skip("needs Chromium for the page (apt-get install chromium)")
    from playwright.sync_api import sync_playwright

    course, jupyter = home / "msdlab", home / "jupyter"
    jupyter.mkdir(exist_ok=True)
    path = course / "notebooks" / "task2.ipynb"
    with (
        jupyterlab_server(jupyter, root=course) as (url, token),
        sync_playwright() as playwright,
    ):
        browser = launch(playwright)
        page = browser.new_page(viewport={"width": 1400, "height": 1200})
        page.set_default_timeout(120_000)
        run_notebook(page, url, token, "notebooks/task2.ipynb")
        shown = page.locator(".jp-OutputArea-output").filter(has_text="total:")
        shown.first.wait_for(timeout=300_000)  # the check cell, the last, has run
        before = path.stat().st_mtime_ns
        page.evaluate("() => window.jupyterapp.commands.execute('docmanager:save')")
        wait_until(lambda: path.stat().st_mtime_ns != before, 60, "JupyterLab saving")
        browser.close()
    status = subprocess.run(
        ["git", "status", "--porcelain"], cwd=course, capture_output=True, text=True, check=True
    )
    assert status.stdout == "", status.stdout
