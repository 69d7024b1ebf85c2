"""Hand-in times from each source: zip entries, file times, git commits, Gradescope."""

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
from msdlab.instructor.handin import handed_in

SOLUTIONS = PROJECT_ROOT / "solutions"
BERLIN_WINTER = timezone(timedelta(hours=1))


def entry_of(path: Path) -> intake.Entry:
    with intake.from_paths([path]) as found:
        return found.entries[0]


def test_zip_entry_times_are_wall_clock_time_unless_they_carry_utc(tmp_path):
    archive = tmp_path / "alice.zip"
    with zipfile.ZipFile(archive, "w") as bundle:
        bundle.writestr(zipfile.ZipInfo("alice/task1.py", (2027, 3, 2, 1, 10, 0)), "x = 1\n")
        bundle.writestr(zipfile.ZipInfo("alice/README.txt", (2027, 3, 9, 0, 0, 0)), "later\n")
    entry = intake.Entry("alice", archive, tmp_path)
    read = handed_in(entry, "auto", BERLIN_WINTER, None, tmp_path)
    assert read.source == "zip entry times"
    assert read.time == datetime(2027, 3, 2, 1, 10, tzinfo=BERLIN_WINTER)  # task files only
    stamped = zipfile.ZipInfo("task1.py", (2027, 3, 2, 1, 10, 0))
    utc = datetime(2027, 3, 1, 22, 0, tzinfo=timezone.utc)
    stamped.extra = struct.pack("<HHBi", 0x5455, 5, 1, int(utc.timestamp()))
    with zipfile.ZipFile(archive, "w") as bundle:
        bundle.writestr(stamped, "x = 1\n")
    assert handed_in(entry, "zip", BERLIN_WINTER, None, tmp_path).time == utc


def test_file_times_are_the_newest_task_file(tmp_path):
    folder = tmp_path / "bob" / "assignments"
    folder.mkdir(parents=True)
    for task, hour in ((1, 9), (2, 23)):
        shutil.copy(SOLUTIONS / f"task{task}.py", folder)
        moment = datetime(2027, 3, 1, hour, tzinfo=timezone.utc).timestamp()
        os.utime(folder / f"task{task}.py", (moment, moment))
    read = handed_in(entry_of(folder), "auto", None, None, tmp_path)
    assert read.source == "file modification time"
    assert read.time == datetime(2027, 3, 1, 23, tzinfo=timezone.utc)


def test_gradescope_metadata_gives_the_submission_time(tmp_path):
    folder = tmp_path / "carol"
    folder.mkdir()
    shutil.copy(SOLUTIONS / "task1.py", folder)
    (folder / "submission_metadata.json").write_text(
        json.dumps({"id": 1, "created_at": "2027-03-01T14:22:32.365935-07:00"})
    )
    read = handed_in(entry_of(folder), "auto", None, None, tmp_path)
    assert read.source == "Gradescope's submission time"
    assert read.time == datetime(2027, 3, 1, 21, 22, 32, 365935, tzinfo=timezone.utc)


def git(repository: Path, *arguments: str, when: str = "") -> None:
    environment = dict(os.environ, GIT_AUTHOR_DATE=when, GIT_COMMITTER_DATE=when)
    for role in ("AUTHOR", "COMMITTER"):
        environment.update({f"GIT_{role}_NAME": "student", f"GIT_{role}_EMAIL": "s@example.org"})
    subprocess.run(
        ["git", "-C", str(repository), *arguments], check=True, capture_output=True, env=environment
    )


def test_git_takes_the_last_commit_before_the_cutoff_and_grades_its_files(tmp_path):
    repository = tmp_path / "dave"
    (repository / "assignments").mkdir(parents=True)
    git(repository, "init", "-q")
    task1 = repository / "assignments" / "task1.py"
    shutil.copy(SOLUTIONS / "task1.py", task1)
    git(repository, "add", ".")
    git(repository, "commit", "-qm", "done", when="2027-03-01T20:00:00+00:00")
    task1.write_text("# rewritten after the cutoff\n")
    git(repository, "commit", "-qam", "too late", when="2027-03-09T20:00:00+00:00")
    cutoff = datetime(2027, 3, 5, tzinfo=timezone.utc)
    read = handed_in(entry_of(repository), "auto", None, cutoff, tmp_path / "scratch")
    assert read.source == "last commit"
    assert read.time == datetime(2027, 3, 1, 20, tzinfo=timezone.utc)
    assert (read.folder / "task1.py").read_bytes() == (SOLUTIONS / "task1.py").read_bytes()
    assert "commits after the cutoff ignored" in read.note
    latest = handed_in(entry_of(repository), "git", None, None, tmp_path / "scratch")
    assert latest.time == datetime(2027, 3, 9, 20, tzinfo=timezone.utc) and latest.note is None


@pytest.mark.parametrize("source", ["git", "gradescope"])
def test_a_source_that_is_not_there_says_so(tmp_path, source):
    folder = tmp_path / "erin"
    folder.mkdir()
    shutil.copy(SOLUTIONS / "task1.py", folder)
    read = handed_in(entry_of(folder), source, None, None, tmp_path)
    assert read.time is None and read.note.startswith("hand-in time unknown")
