"""Links are not submissions: a submission that is a symbolic link, lies below one, leads
outside the folder it was handed in, or is a zip holding a link gets a row under its own
name with 0 points and a note saying why; the run's exit status is 1. The ``source``
column names every folder exactly, whatever the bytes of its name."""

from __future__ import annotations

import csv
import os
import shutil
import stat
import zipfile
from pathlib import Path

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor import intake

SOLUTIONS = PROJECT_ROOT / "solutions"
CHECKS = PROJECT_ROOT / "tests" / "tasks"


def folder_of_tasks(path: Path, *tasks: int) -> Path:
    path.mkdir(parents=True)
    for task in tasks:
        shutil.copy(SOLUTIONS / f"task{task}.py", path)
    return path


def zip_with_a_link(path: Path) -> Path:
    with zipfile.ZipFile(path, "w") as bundle:
        bundle.write(SOLUTIONS / "task1.py", "work/task1.py")
        link = zipfile.ZipInfo("work/task2.py")
        link.external_attr = (stat.S_IFLNK | 0o777) << 16
        bundle.writestr(link, str(SOLUTIONS / "task2.py"))
    return path


def test_a_link_a_link_to_a_parent_and_a_zip_with_links_are_refused(tmp_path):
    course = folder_of_tasks(tmp_path / "course" / "solutions", 1)
    alice = folder_of_tasks(tmp_path / "class" / "alice" / "assignments", 1)
    mallory = tmp_path / "class" / "mallory" / "assignments"
    mallory.parent.mkdir()
    mallory.symlink_to(course, target_is_directory=True)
    eve = tmp_path / "class" / "eve" / "assignments"
    eve.parent.mkdir()
    eve.symlink_to("..", target_is_directory=True)  # a link to a parent folder
    (tmp_path / "class" / "trudy").symlink_to(course.parent, target_is_directory=True)
    trudy = tmp_path / "class" / "trudy" / "solutions"  # below a link
    oscar = zip_with_a_link(tmp_path / "class" / "oscar.zip")
    with intake.from_paths([alice, mallory, eve, trudy, oscar]) as found:
        entries = {entry.id: entry for entry in found.entries}
    assert sorted(entries) == ["alice", "eve", "mallory", "oscar", "trudy/solutions"]
    assert entries["alice"].problem is None
    for name in ("mallory", "eve", "trudy/solutions"):
        assert "symbolic link" in entries[name].problem, entries[name].problem
    assert "symbolic link" in entries["oscar"].problem
    assert entries["mallory"].source == mallory


def test_a_roster_path_outside_its_folder_through_a_link_is_refused(tmp_path):
    course = folder_of_tasks(tmp_path / "course" / "solutions", 1)
    roster_folder = tmp_path / "roster"
    roster_folder.mkdir()
    (roster_folder / "mallory").symlink_to(course, target_is_directory=True)
    roster = roster_folder / "roster.csv"
    roster.write_text("mallory,mallory\n")
    with intake.from_roster(roster) as found:
        (entry,) = found.entries
    assert entry.id == "mallory" and "symbolic link" in entry.problem


def test_grade_gives_a_linked_submission_its_row_with_0_and_exit_status_1(tmp_path, capsys):
    checks = folder_of_tasks(tmp_path / "checks")
    for name in ("conftest.py", "test_task1.py", "test_task1_hidden.py", "reference_hidden.py"):
        shutil.copy(CHECKS / name, checks)
    odd = os.fsdecode(b"caf\xe9 \\x")  # not UTF-8, and a backslash
    student = folder_of_tasks(tmp_path / "class" / odd, 1)
    mallory = tmp_path / "class" / "mallory"
    mallory.symlink_to(checks.parent / "class" / odd, target_is_directory=True)
    out = tmp_path / "grades.csv"
    given = [str(student), str(mallory), "--out", str(out), "--checks", str(checks)]
    assert main(["grade", *given, "--call-timeout", "20"]) == 1
    capsys.readouterr()
    rows = {row["id"]: row for row in csv.DictReader(out.open(encoding="utf-8"))}
    assert rows["mallory"]["total"] == "0" and "symbolic link" in rows["mallory"]["notes"]
    assert rows["mallory"]["source"] == str(mallory)
    (graded,) = [row for row in rows.values() if row["id"].startswith("caf")]
    assert int(graded["total"]) > 0
    assert graded["source"] == str(tmp_path / "class") + "/caf\\xe9 \\\\x"
    assert os.fsencode(intake.unescaped(graded["source"])) == os.fsencode(str(student))
