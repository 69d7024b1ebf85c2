"""Hand-in times from each source (zip entries, file times, git commits, Gradescope), each
with who controls it."""

from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
import zipfile
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

from msdlab.course import PROJECT_ROOT
from msdlab.instructor import intake

SOLUTIONS = PROJECT_ROOT / "solutions"
BERLIN_WINTER = timezone(timedelta(hours=1))
DUE = datetime(2027, 3, 2, tzinfo=timezone.utc)


def taken(path: Path, scratch: list, **rules: object) -> intake.Entry:
    """``path`` taken in alone, due `DUE` (the intake's folders live while the test runs)."""
    found = intake.Intake(intake.Rules(due_of=lambda identifier: DUE, **rules))
    scratch.append(found)
    return found.add(path.stem, path)


@pytest.fixture
def scratch():
    opened: list[intake.Intake] = []
    yield opened
    for found in opened:
        found.close()


def test_zip_entry_times_are_wall_clock_time_unless_they_carry_utc(tmp_path, scratch):
    archive = tmp_path / "alice.zip"
    with zipfile.ZipFile(archive, "w") as bundle:
        bundle.writestr(zipfile.ZipInfo("alice/task1.py", (2027, 3, 2, 1, 10, 0)), "x = 1\n")
        bundle.writestr(zipfile.ZipInfo("alice/README.txt", (2027, 3, 9, 0, 0, 0)), "later\n")
    read = taken(archive, scratch, zone=BERLIN_WINTER).handed_in
    assert (read.source, read.control) == ("zip entry times", "student")
    assert read.time == datetime(2027, 3, 2, 1, 10, tzinfo=BERLIN_WINTER)  # task files only
    stamped = zipfile.ZipInfo("task1.py", (2027, 3, 2, 1, 10, 0))
    utc = datetime(2027, 3, 1, 22, 0, tzinfo=timezone.utc)
    stamped.extra = struct.pack("<HHBi", 0x5455, 5, 1, int(utc.timestamp()))
    with zipfile.ZipFile(archive, "w") as bundle:
        bundle.writestr(stamped, "x = 1\n")
    assert taken(archive, scratch, source="zip", zone=BERLIN_WINTER).handed_in.time == utc


def test_file_times_are_the_newest_task_file(tmp_path, scratch):
    folder = tmp_path / "bob" / "assignments"
    folder.mkdir(parents=True)
    for task, hour in ((1, 9), (2, 23)):
        shutil.copy(SOLUTIONS / f"task{task}.py", folder)
        moment = datetime(2027, 3, 1, hour, tzinfo=timezone.utc).timestamp()
        os.utime(folder / f"task{task}.py", (moment, moment))
    read = taken(folder, scratch).handed_in
    assert (read.source, read.control) == ("file modification time", "student")
    assert read.time == datetime(2027, 3, 1, 23, tzinfo=timezone.utc)


def test_gradescope_metadata_beside_the_submission_is_the_instructors(tmp_path, scratch):
    root = tmp_path / "carol"
    (root / "submission").mkdir(parents=True)
    shutil.copy(SOLUTIONS / "task1.py", root / "submission")
    (root / "submission_metadata.json").write_text(
        json.dumps({"id": 1, "created_at": "2027-03-01T14:22:32.365935-07:00"})
    )
    entry = taken(root, scratch)
    assert (entry.handed_in.source, entry.handed_in.control) == (
        "Gradescope's submission time",
        "instructor",
    )
    assert entry.handed_in.time == datetime(2027, 3, 1, 21, 22, 32, 365935, tzinfo=timezone.utc)
    assert (entry.folder / "task1.py").is_file() and not any("verified" in n for n in entry.notes)


def git(repository: Path, *arguments: str, when: str = "") -> None:
    """Run git to BUILD a test's repository (never on a submission in the grader)."""
    environment = dict(os.environ, GIT_AUTHOR_DATE=when, GIT_COMMITTER_DATE=when)
    for role in ("AUTHOR", "COMMITTER"):
        environment.update({f"GIT_{role}_NAME": "student", f"GIT_{role}_EMAIL": "s@example.org"})
    subprocess.run(
        ["git", "-C", str(repository), *arguments], check=True, capture_output=True, env=environment
    )


def test_git_takes_the_last_commit_before_the_cutoff_and_grades_its_files(tmp_path, scratch):
    repository = tmp_path / "dave"
    (repository / "assignments").mkdir(parents=True)
    git(repository, "init", "-q")
    task1 = repository / "assignments" / "task1.py"
    shutil.copy(SOLUTIONS / "task1.py", task1)
    git(repository, "add", ".")
    git(repository, "commit", "-qm", "done", when="2027-03-01T20:00:00+00:00")
    task1.write_text("# rewritten after the cutoff\n")
    git(repository, "commit", "-qam", "too late", when="2027-03-09T20:00:00+00:00")
    entry = taken(repository, scratch, cutoff=timedelta(days=3))
    read = entry.handed_in
    assert (read.source, read.control) == ("last commit", "student")
    assert read.time == datetime(2027, 3, 1, 20, tzinfo=timezone.utc)
    assert (entry.folder / "task1.py").read_bytes() == (SOLUTIONS / "task1.py").read_bytes()
    assert any("commits after the cutoff ignored" in note for note in entry.notes)
    latest = taken(repository, scratch).handed_in
    assert latest.time == datetime(2027, 3, 9, 20, tzinfo=timezone.utc) and latest.note is None


def test_the_classroom_layout_of_the_docs_is_read_as_a_repository(tmp_path, scratch):
    """``msdlab grade class/*/assignments`` of Classroom clones: the commit, not file times."""
    repository = tmp_path / "class" / "erin"
    (repository / "assignments").mkdir(parents=True)
    git(repository, "init", "-q")
    shutil.copy(SOLUTIONS / "task1.py", repository / "assignments")
    git(repository, "add", ".")
    git(repository, "commit", "-qm", "done", when="2027-03-01T20:00:00+00:00")
    with intake.from_paths([repository / "assignments"]) as found:
        (entry,) = found.entries
        assert entry.id == "erin" and entry.handed_in.source == "last commit"
        assert entry.handed_in.time == datetime(2027, 3, 1, 20, tzinfo=timezone.utc)
        assert (entry.folder / "task1.py").is_file()


@pytest.mark.parametrize("source", ["git", "gradescope"])
def test_a_source_that_is_not_there_says_so(tmp_path, scratch, source):
    folder = tmp_path / "erin"
    folder.mkdir()
    shutil.copy(SOLUTIONS / "task1.py", folder)
    entry = taken(folder, scratch, source=source)
    assert entry.handed_in.time is None and entry.handed_in.control == "unreadable"
    assert any(note.startswith("hand-in time unreadable") for note in entry.notes)
    assert any(note.startswith("hand-in time not verified") for note in entry.notes)
