"""The intake as a dishonest student attacks it: a crafted repository, a planted file, a
forged time, a link, a lookalike id. Each test builds what the student hands in (git
repositories with dulwich, or with git in the test's own folder) and asserts that nothing
outside the sandbox ran or was written, and that the row says what could not be verified.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import stat
import zipfile
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest
from dulwich.objects import Blob, Commit, Tree
from dulwich.repo import Repo

from msdlab.cli import build_parser, main
from msdlab.course import PROJECT_ROOT, own_numbers
from msdlab.instructor import intake

SOLUTIONS = PROJECT_ROOT / "solutions"
TASK1 = (SOLUTIONS / "task1.py").read_bytes()
DUE = datetime(2027, 3, 1, 23, 59, tzinfo=timezone.utc)
BEFORE, AFTER = DUE - timedelta(days=1), DUE + timedelta(days=5)
FILE, LINK, SUBMODULE = 0o100644, 0o120000, 0o160000


@pytest.fixture
def take():
    """``take(path, **rules)``: the entry of ``path`` taken in alone, due `DUE`."""
    opened: list[intake.Intake] = []

    def taken(path: Path, identifier: str = "alice", **rules: object) -> intake.Entry:
        found = intake.Intake(intake.Rules(due_of=lambda student: DUE, **rules))
        opened.append(found)
        return found.add(identifier, path)

    yield taken
    for found in opened:
        found.close()


def tree(store, files: dict[bytes, tuple[int, bytes]]) -> bytes:
    """A tree of ``files`` (name -> (mode, content or id)), ``a/b`` names in folders."""
    top, folders = Tree(), {}
    for name, (mode, content) in files.items():
        folder, _, rest = name.partition(b"/")
        if rest and not name.startswith(b"/") and b".." not in name:
            folders.setdefault(folder, {})[rest] = (mode, content)
            continue
        if mode == SUBMODULE:
            top.add(name, mode, content)
        else:
            blob = Blob.from_string(content)
            store.add_object(blob)
            top.add(name, mode, blob.id)
    for folder, inside in folders.items():
        top.add(folder, stat.S_IFDIR, tree(store, inside))
    store.add_object(top)
    return top.id


def repository(folder: Path, *commits: tuple[dict[bytes, tuple[int, bytes]], datetime],
               signed: bool = False) -> Repo:  # fmt: skip
    """A git repository at ``folder`` holding ``commits`` (files, committer time), oldest
    first, on its branch master; its work tree holds the last commit's files."""
    folder.mkdir(parents=True, exist_ok=True)
    repo = Repo.init(str(folder))
    parent = []
    for files, moment in commits:
        commit = Commit()
        commit.tree = tree(repo.object_store, files)
        commit.author = commit.committer = b"Student <student@example.org>"
        commit.author_time = commit.commit_time = int(moment.timestamp())
        commit.author_timezone = commit.commit_timezone = 0
        commit.message, commit.parents = b"work\n", parent
        if signed:
            commit.gpgsig = b"-----BEGIN PGP SIGNATURE-----\n\nx\n-----END PGP SIGNATURE-----\n"
        repo.object_store.add_object(commit)
        parent = [commit.id]
    repo.refs[b"refs/heads/master"] = parent[0]
    for name, (mode, content) in commits[-1][0].items():
        if mode == FILE and b".." not in name and not name.startswith(b"/"):
            (folder / os.fsdecode(name)).parent.mkdir(parents=True, exist_ok=True)
            (folder / os.fsdecode(name)).write_bytes(content)
    return repo


def hostile_config(git_folder: Path, marker: Path) -> None:
    """Every setting and hook of a ``.git`` that makes git run a program: each one runs a
    script that writes ``marker``."""
    script = git_folder.parent / "payload.sh"
    script.write_text(f"#!/bin/sh\necho ran >> {marker}\n")
    script.chmod(0o755)
    with (git_folder / "config").open("a") as config:
        config.write(
            f"[core]\n\tfsmonitor = {script}\n\tpager = {script}\n\tsshCommand = {script}\n"
            f"[gpg]\n\tprogram = {script}\n[log]\n\tshowSignature = true\n"
            f'[diff]\n\texternal = {script}\n[filter "x"]\n\tsmudge = {script}\n'
            f"[alias]\n\tlog = !{script}\n"
        )
    (git_folder.parent / ".gitattributes").write_text("* filter=x\n")
    for hook in ("post-checkout", "pre-commit", "post-merge", "reference-transaction"):
        shutil.copy(script, git_folder / "hooks" / hook)


# ------------------------------------------------- a repository runs nothing of its own
def test_a_repository_whose_config_names_programs_runs_none_of_them(tmp_path, take):
    marker = tmp_path / "ran-the-students-program"
    alice = tmp_path / "class" / "alice"
    on_time = {b"assignments/task1.py": (FILE, TASK1)}
    too_late = {b"assignments/task1.py": (FILE, b"# after the cutoff\n")}
    repository(alice, (on_time, BEFORE), (too_late, AFTER), signed=True)
    hostile_config(alice / ".git", marker)
    entry = take(alice / "assignments", cutoff=timedelta(days=2))
    assert not marker.exists()
    assert entry.problem is None and (entry.folder / "task1.py").read_bytes() == TASK1
    assert entry.handed_in.time == BEFORE.replace(microsecond=0)
    assert (entry.handed_in.source, entry.handed_in.control) == ("last commit", "student")


@pytest.mark.parametrize("name", [b"/tmp/attack/pwned.py", b"..", b"../x.py", b"a/../../x.py"])
def test_a_tree_naming_a_path_outside_its_folder_writes_nothing(tmp_path, take, name):
    target = tmp_path / "outside.py"
    name = name.replace(b"/tmp/attack/pwned.py", os.fsencode(target))
    mallory = tmp_path / "mallory"
    repository(mallory, ({b"task1.py": (FILE, TASK1), name: (FILE, b"import os\n")}, BEFORE))
    entry = take(mallory)
    assert "not graded: the commit's tree holds" in entry.problem
    assert not target.exists() and not (tmp_path / "x.py").exists()


def test_a_tree_outside_the_graded_folder_is_never_read(tmp_path, take):
    target = tmp_path / "pwned.py"
    mallory = tmp_path / "mallory"
    files = {b"assignments/task1.py": (FILE, TASK1), os.fsencode(target): (FILE, b"x = 1\n")}
    repository(mallory, (files, BEFORE))
    entry = take(mallory / "assignments")
    assert entry.problem is None and not target.exists()
    assert sorted(path.name for path in entry.folder.iterdir()) == ["task1.py"]


def test_links_and_submodules_in_a_commit_are_left_out(tmp_path, take):
    mallory = tmp_path / "mallory"
    files = {
        b"task1.py": (FILE, TASK1),
        b"task2.py": (LINK, os.fsencode(SOLUTIONS / "task2.py")),
        b"task3.py": (SUBMODULE, b"1" * 40),
        b".git/config": (FILE, b"[core]\n"),
    }
    repository(mallory, ({k: v for k, v in files.items() if b".git" not in k}, BEFORE))
    entry = take(mallory)
    assert sorted(path.name for path in entry.folder.iterdir()) == ["task1.py"]
    assert any("task2.py was left out: a symbolic link in the commit" in n for n in entry.notes)
    assert any("task3.py was left out: a submodule" in n for n in entry.notes)
    eve = tmp_path / "eve"
    repository(eve, (files, BEFORE))
    assert "inside a .git folder" in take(eve).problem


def test_a_git_file_pointing_at_another_students_repository_is_refused(tmp_path, take):
    bob = tmp_path / "class" / "bob"
    repository(bob, ({b"task1.py": (FILE, TASK1)}, BEFORE))
    alice = tmp_path / "class" / "alice"
    alice.mkdir()
    (alice / "task1.py").write_text("# the template\n")
    (alice / ".git").write_text("gitdir: ../bob/.git\n")
    entry = take(alice)
    assert entry.problem.startswith("not graded: its .git is a file naming another repository")
    assert "gitdir: ../bob/.git" in entry.problem


@pytest.mark.parametrize("borrowed", ["objects/info/alternates", "commondir"])
def test_a_repository_borrowing_another_ones_objects_is_refused(tmp_path, take, borrowed):
    bob = tmp_path / "bob"
    repository(bob, ({b"task1.py": (FILE, TASK1)}, BEFORE))
    alice = tmp_path / "alice"
    shutil.copytree(bob, alice)
    (alice / ".git" / borrowed).write_text(f"{bob / '.git' / 'objects'}\n")
    assert "borrows from another repository" in take(alice).problem


def test_a_git_folder_holding_a_link_is_refused(tmp_path, take):
    bob = tmp_path / "bob"
    repository(bob, ({b"task1.py": (FILE, TASK1)}, BEFORE))
    alice = tmp_path / "alice"
    shutil.copytree(bob, alice)
    shutil.rmtree(alice / ".git" / "objects")
    (alice / ".git" / "objects").symlink_to(bob / ".git" / "objects")
    assert "its .git holds a symbolic link (objects)" in take(alice).problem


def test_an_empty_git_folder_is_an_unreadable_time_and_the_files_are_graded(tmp_path, take):
    alice = tmp_path / "alice"
    (alice / ".git").mkdir(parents=True)
    (alice / "task1.py").write_bytes(TASK1)
    entry = take(alice)
    assert entry.problem is None and (entry.folder / "task1.py").read_bytes() == TASK1
    assert entry.handed_in.time is None and entry.handed_in.control == "unreadable"
    assert any(n.startswith("hand-in time not verified: last commit (none)") for n in entry.notes)


# ------------------------------------------------- times the student controls are marked
def test_a_planted_gradescope_metadata_file_is_ignored_in_a_folder_and_a_zip(tmp_path, take):
    planted = json.dumps({"created_at": BEFORE.isoformat()})
    folder = tmp_path / "alice"
    folder.mkdir()
    (folder / "task1.py").write_bytes(TASK1)
    (folder / "submission_metadata.json").write_text(planted)
    late = AFTER.timestamp()
    os.utime(folder / "task1.py", (late, late))
    with zipfile.ZipFile(tmp_path / "bob.zip", "w") as bundle:
        bundle.writestr(zipfile.ZipInfo("task1.py", AFTER.timetuple()[:6]), TASK1)
        bundle.writestr("submission_metadata.json", planted)
    for entry in (take(folder), take(tmp_path / "bob.zip", zone=timezone.utc)):
        assert entry.handed_in.control == "student" and entry.handed_in.time == AFTER
        assert any("submission_metadata.json among the student's files was ignored" in n
                   for n in entry.notes)  # fmt: skip


def forged(tmp_path: Path) -> dict[str, Path]:
    """A backdated commit, a zip with forged entry times, and touched files: all 'on time'."""
    commit = tmp_path / "commit"
    repository(commit, ({b"task1.py": (FILE, TASK1)}, BEFORE))
    archive = tmp_path / "archive.zip"
    with zipfile.ZipFile(archive, "w") as bundle:
        bundle.writestr(zipfile.ZipInfo("task1.py", BEFORE.timetuple()[:6]), TASK1)
    touched = tmp_path / "touched"
    touched.mkdir()
    (touched / "task1.py").write_bytes(TASK1)
    os.utime(touched / "task1.py", (BEFORE.timestamp(), BEFORE.timestamp()))
    return {"commit": commit, "archive": archive, "touched": touched}


@pytest.mark.parametrize("form", ["commit", "archive", "touched"])
def test_a_forged_time_is_flagged_by_default_taken_on_accept_and_charged_on_late(
    tmp_path, take, form
):
    path = forged(tmp_path)[form]
    flagged = take(path, zone=timezone.utc)
    assert flagged.handed_in.time == BEFORE.replace(microsecond=0)
    assert flagged.handed_in.control == "student"
    assert any(n.startswith("hand-in time not verified") for n in flagged.notes)
    accepted = take(path, zone=timezone.utc, unverified="accept")
    assert accepted.handed_in.time == BEFORE.replace(microsecond=0)
    assert not any("not verified" in n for n in accepted.notes)
    collected = datetime(2027, 3, 9, 12, tzinfo=timezone.utc)
    charged = take(path, zone=timezone.utc, unverified="late", collected=collected)
    assert charged.handed_in.time == collected and charged.handed_in.control == "student"
    assert any("charged as handed in when it was taken in" in n for n in charged.notes)


def test_unreadable_times_are_marked_unreadable(tmp_path, take):
    with zipfile.ZipFile(tmp_path / "month0.zip", "w") as bundle:
        bundle.writestr(zipfile.ZipInfo("task1.py", (2027, 0, 1, 0, 0, 0)), TASK1)
    upload = tmp_path / "upload"
    (upload / "submission").mkdir(parents=True)
    (upload / "submission" / "task1.py").write_bytes(TASK1)
    (upload / "submission_metadata.json").write_text("{}")
    for entry in (take(tmp_path / "month0.zip"), take(upload)):
        assert entry.problem is None and entry.handed_in.time is None
        assert entry.handed_in.control == "unreadable"
        assert any(n.startswith("hand-in time not verified") for n in entry.notes)


# ------------------------------------------------- links inside a submission are not followed
def test_links_in_a_folder_and_a_zip_are_not_followed(tmp_path, take):
    secret = tmp_path / "solutions" / "task2.py"
    secret.parent.mkdir()
    secret.write_bytes(b"# the course's solution\n")
    folder = tmp_path / "mallory"
    folder.mkdir()
    (folder / "task1.py").write_bytes(TASK1)
    (folder / "task2.py").symlink_to(secret)
    (folder / "assignments").symlink_to(secret.parent, target_is_directory=True)
    with zipfile.ZipFile(tmp_path / "eve.zip", "w") as bundle:
        bundle.writestr("task1.py", TASK1)
        link = zipfile.ZipInfo("task2.py")
        link.external_attr = (stat.S_IFLNK | 0o777) << 16
        bundle.writestr(link, str(secret))
    for entry in (take(folder), take(tmp_path / "eve.zip")):
        assert sorted(path.name for path in entry.folder.iterdir()) == ["task1.py"]
        assert any("task2.py was left out" in note for note in entry.notes)


# ------------------------------------------------- ids come from the roster
def test_a_path_id_the_roster_does_not_know_gets_a_row_saying_so_and_is_not_graded(tmp_path):
    alice = tmp_path / "class" / "sec1" / "alice"
    alice.mkdir(parents=True)
    (alice / "task1.py").write_bytes(TASK1)
    bob = tmp_path / "class" / "bob"
    bob.mkdir()
    (bob / "task1.py").write_bytes(TASK1)
    with intake.from_paths([alice, bob], known={"alice", "bob"}) as found:
        unlisted, graded = found.entries
        assert [unlisted.id, graded.id] == ["sec1/alice", "bob"] and not found.refused
        assert "the id 'sec1/alice', which is not on the roster" in unlisted.problem
        assert graded.problem is None


def test_the_roster_gives_the_id_whatever_the_path(tmp_path):
    (tmp_path / "sec1" / "alice").mkdir(parents=True)
    (tmp_path / "sec1" / "alice" / "task1.py").write_bytes(TASK1)
    with zipfile.ZipFile(tmp_path / "carol_12345_task.zip", "w") as bundle:
        bundle.writestr("task1.py", TASK1)
    roster = tmp_path / "roster.csv"
    roster.write_text("id,folder,name\nalice,sec1/alice,Alice\ncarol,carol_12345_task.zip,C\n")
    with intake.from_roster(roster) as found:
        assert [entry.id for entry in found.entries] == ["alice", "carol"]


@pytest.mark.parametrize(
    ("name", "why"),
    [
        ("(max points)", "the gradebook's row of maximum points"),
        ("bob ", "has spaces around it"),
        ("Bob", "looks like 'bob'"),
        ("'bob", 'starts with "\'"'),
        ("=HYPERLINK(1)", "starts with '='"),
        ("+1", "starts with '+'"),
        ("-x", "starts with '-'"),
        ("@x", "starts with '@'"),
    ],
)
def test_a_lookalike_or_reserved_id_is_refused_and_the_rest_taken(tmp_path, name, why):
    paths = []
    for folder in ("bob", name):
        (tmp_path / "class" / folder).mkdir(parents=True)
        (tmp_path / "class" / folder / "task1.py").write_bytes(TASK1)
        paths.append(tmp_path / "class" / folder)
    with intake.from_paths(paths) as found:
        assert [entry.id for entry in found.entries] == ["bob"]
        (refused,) = found.refused
    assert why in refused and "--roster" in refused


# ------------------------------------------------- the grader: one refused, the class graded
CHECKS = PROJECT_ROOT / "tests" / "tasks"


def course_with_task1_checks(root: Path, own: bool) -> Path:
    """A course folder holding task 1's checks in tests/tasks (own numbers on or off)."""
    checks = root / "tests" / "tasks"
    checks.mkdir(parents=True)
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(CHECKS / name, checks)
    (root / own_numbers.SETTINGS_FILE).write_text(json.dumps({"own_numbers": own}))
    return checks


def rows_of(path: Path) -> dict[str, dict[str, str]]:
    return {row["id"]: row for row in csv.DictReader(path.open(encoding="utf-8"))}


def test_own_numbers_come_from_the_roster_whatever_the_path(tmp_path, capsys):
    checks = course_with_task1_checks(tmp_path / "course", own=True)
    for student, where in (("alice", "sec1/alice"), ("carol", "carol_12345_task")):
        folder = tmp_path / "class" / where
        folder.mkdir(parents=True)
        own = own_numbers.personalised(1, TASK1.decode(), own_numbers.numbers(student))
        (folder / "task1.py").write_text(own, encoding="utf-8")
    shutil.make_archive(str(tmp_path / "class" / "carol_12345_task"), "zip",
                        tmp_path / "class" / "carol_12345_task")  # fmt: skip
    shutil.rmtree(tmp_path / "class" / "carol_12345_task")
    out = tmp_path / "grades.csv"
    common = ["--out", str(out), "--checks", str(checks), "--jobs", "2", "--call-timeout", "30"]
    given = [str(tmp_path / "class" / "sec1" / "alice"), str(tmp_path / "class" / "x.zip")]
    assert main(["grade", *given, *common]) == 2  # no roster: ids from paths are refused
    assert "give --roster FILE" in capsys.readouterr().err
    roster = tmp_path / "class" / "roster.csv"
    roster.write_text("id,folder\nalice,sec1/alice\ncarol,carol_12345_task.zip\n")
    assert main(["grade", "--roster", str(roster), *common]) == 0, capsys.readouterr().err
    rows = rows_of(out)
    full = rows[intake.MAX_POINTS_ID]["task1"]
    assert rows["alice"]["task1"] == rows["carol"]["task1"] == full != "0"


def test_a_lookalike_id_is_refused_and_the_rest_of_the_class_graded(tmp_path, capsys):
    checks = course_with_task1_checks(tmp_path / "course", own=False)
    given = []
    for name in ("bob", "bob ", "(max points)", "=cmd|' /C calc'!A0"):
        folder = tmp_path / "class" / name
        folder.mkdir(parents=True)
        (folder / "task1.py").write_bytes(TASK1)
        given.append(str(folder))
    out = tmp_path / "grades.csv"
    status = main(["grade", *given, "--out", str(out), "--checks", str(checks),
                   "--call-timeout", "30"])  # fmt: skip
    printed = capsys.readouterr().err
    assert status == 1 and "3 submissions refused for their id" in printed
    for why in ("has spaces around it", "row of maximum points", "starts with '='"):
        assert why in printed
    rows = rows_of(out)
    assert list(rows) == [intake.MAX_POINTS_ID, "bob"]
    assert rows["bob"]["task1"] == rows[intake.MAX_POINTS_ID]["task1"] != "0"


def test_checks_outside_a_course_with_own_numbers_are_refused_not_silently_off(
    tmp_path, monkeypatch
):
    from msdlab.instructor.commands import grade

    course = tmp_path / "course"
    course_with_task1_checks(course, own=True)
    monkeypatch.setattr(grade, "PROJECT_ROOT", course)
    elsewhere = tmp_path / "copy" / "tests" / "tasks"
    shutil.copytree(CHECKS, elsewhere, ignore=shutil.ignore_patterns("__pycache__"))
    arguments = build_parser().parse_args(["grade", "--roster", "r.csv", "--out", "g.csv"])
    with pytest.raises(ValueError, match="lie outside that course"):
        grade.own_numbers_of(elsewhere, arguments)
