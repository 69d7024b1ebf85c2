"""The instructor's grading workflow: which submission is whose, the grades file, and the
feedback to hand out (the sandboxing itself is tested in test_grading.py).

Links are not submissions: a submission that is a symbolic link, lies below one, or leads
outside the folder it was handed in gets a row under its own name with 0 points and a note
saying why; the run's exit status is 1. A link inside a submission (a folder's, a zip's) is
left out, with a note. The ``source``
column names every folder exactly, whatever the bytes of its name."""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT, reference_cache
from msdlab.course.report import CheckReport, CheckResult
from msdlab.instructor import intake
from msdlab.instructor.judging.grading import Grade
from msdlab.instructor.outputs import csv_files, feedback, render
from msdlab.instructor.points import gradebook, gradebook_db
from msdlab.instructor.rules.final_points import Terms

SOLUTIONS = PROJECT_ROOT / "solutions"
CHECKS = PROJECT_ROOT / "tests" / "tasks"


def folder_of_tasks(path: Path, *tasks: int) -> Path:
    path.mkdir(parents=True)
    for task in tasks:
        shutil.copy(SOLUTIONS / f"task{task}.py", path)
    return path


def test_ids_are_paths_relative_to_the_common_parent(tmp_path):
    alice = folder_of_tasks(tmp_path / "class" / "alice" / "assignments", 1)
    bob = folder_of_tasks(tmp_path / "class" / "s2" / "bob" / "assignments", 1)
    with intake.from_paths([alice, bob]) as found:
        assert [e.id for e in found.entries] == ["alice", "s2/bob"]
    with intake.from_paths([alice]) as found:  # one submission keeps its student's name
        assert [e.id for e in found.entries] == ["alice"]


def test_bundle_folders_zips_and_empty_folders(tmp_path):
    folder_of_tasks(tmp_path / "carol" / "assignments", 1, 2)
    (tmp_path / "dave").mkdir()
    (tmp_path / "dave" / "notes.txt").write_text("I did not finish")
    with zipfile.ZipFile(tmp_path / "erin.zip", "w") as bundle:
        bundle.write(SOLUTIONS / "task1.py", "erin-work/task1.py")
    with zipfile.ZipFile(tmp_path / "evil.zip", "w") as bundle:
        bundle.writestr("../task1.py", "print('escaped')")
    paths = [tmp_path / name for name in ("carol", "dave", "erin.zip", "evil.zip")]
    with intake.from_paths(paths) as found:
        carol, dave, erin, evil = found.entries
        assert carol.problem is None and carol.folder != tmp_path / "carol" / "assignments"
        assert sorted(p.name for p in carol.folder.iterdir()) == ["task1.py", "task2.py"]
        assert not carol.notes  # the usual hand-in form: nothing to note
        assert "no task files" in dave.problem
        assert erin.id == "erin" and (erin.folder / "task1.py").is_file()
        assert "leads out of its folder" in evil.problem
        fresh = [carol.folder, erin.folder]
    assert not any(folder.exists() for folder in fresh)  # fresh folders go when it closes


def test_any_folder_name_gives_a_readable_unique_id_and_a_bounded_file_name(tmp_path):
    odd = os.fsdecode(b"caf\xe9")  # not UTF-8
    long = "x" * 200
    paths = [
        folder_of_tasks(tmp_path / name, 1) for name in (odd, "caf\N{REPLACEMENT CHARACTER}", long)
    ]
    with intake.from_paths(paths) as found:
        ids = [e.id for e in found.entries]
        refused = found.refused
    # the undecodable name reads as the other: the second of the two is refused, not renamed
    assert len(set(ids)) == 2 and all(i.encode("utf-8") for i in ids)
    assert len(refused) == 1 and "a submission taken in before it" in refused[0]
    stems = [intake.file_stem(i) for i in [*ids, os.fsdecode(b"caf\xe9")]]
    assert len(set(stems)) == 3 and max(map(len, stems)) <= intake.MAX_STEM
    assert intake.file_stem("alice") == "alice"
    assert intake.file_stem("../../etc") != intake.file_stem("etc") and "/" not in intake.file_stem(
        "a/b"
    )


def test_roster_gives_ids_and_refuses_repeats(tmp_path):
    folder_of_tasks(tmp_path / "sub1", 1)
    roster = tmp_path / "roster.csv"
    roster.write_text("id,folder\nalice,sub1\n")
    with intake.from_roster(roster) as found:
        assert [(e.id, e.source) for e in found.entries] == [("alice", tmp_path / "sub1")]
    roster.write_text("id,folder\nalice,sub1\nalice,sub1\n")
    with intake.from_roster(roster) as found:  # the second is refused, the first taken
        assert [e.id for e in found.entries] == ["alice"]
        assert "the id 'alice' is 'alice', a submission taken in before it" in found.refused[0]


@pytest.mark.parametrize("header", ["id,folder", "ID,Submission", "name,id,zip"])
def test_a_roster_names_its_columns_on_its_first_line(tmp_path, header):
    folder_of_tasks(tmp_path / "sub1", 1)
    roster = tmp_path / "roster.csv"
    cells = {"id": "alice", "name": "Alice A."}
    row = ",".join(cells.get(column.lower(), "sub1") for column in header.split(","))
    roster.write_text(f"{header}\n{row}\n")
    with intake.from_roster(roster) as found:
        assert [e.id for e in found.entries] == ["alice"]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("alice,sub1\nbob,sub1\n", "the first line must name the columns, one of them 'id'"),
        ("id,folder\nalice,sub1\n,sub2\n", "line 3: ',sub2' has no id; give each line"),
        ("id,name\nalice,Alice\n", "names no folder or zip file: give a 'folder' column"),
    ],
)
def test_a_malformed_roster_names_its_line_and_the_fix(tmp_path, capsys, text, message):
    folder_of_tasks(tmp_path / "sub1", 1)
    roster = tmp_path / "roster.csv"
    roster.write_text(text)
    assert main(["grade", "--roster", str(roster), "--out", str(tmp_path / "grades.csv")]) == 2
    assert re.search(f"msdlab grade: error: .*roster.csv.*{message}", capsys.readouterr().err)


# ---------------------------------------- links are not submissions; exact sources
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
        oscar_files = sorted(path.name for path in entries["oscar"].folder.iterdir())
    assert sorted(entries) == ["alice", "eve", "mallory", "oscar", "trudy/solutions"]
    assert entries["alice"].problem is None
    for name in ("mallory", "eve", "trudy/solutions"):
        assert "symbolic link" in entries[name].problem, entries[name].problem
    assert entries["oscar"].problem is None and oscar_files == ["task1.py"]  # the link left out
    assert any("task2.py was left out: a symbolic link" in n for n in entries["oscar"].notes)
    assert entries["mallory"].source == mallory


def test_a_roster_path_outside_its_folder_through_a_link_is_refused(tmp_path):
    course = folder_of_tasks(tmp_path / "course" / "solutions", 1)
    roster_folder = tmp_path / "roster"
    roster_folder.mkdir()
    (roster_folder / "mallory").symlink_to(course, target_is_directory=True)
    roster = roster_folder / "roster.csv"
    roster.write_text("id,folder\nmallory,mallory\n")
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


def report(*checks: CheckResult) -> CheckReport:
    return CheckReport("submission", list(checks))


PUBLIC_FAIL = CheckResult(
    "t::test_a", "rest_state", 2, 2, False, "failed", "CheckFailed",
    "net force 0.5 at /tmp/msdlab-grade-ab12/submission/task2.py line 3",
)  # fmt: skip
PUBLIC_PASS = CheckResult("t::test_b", "pulls", 2, 3, False, "passed")
HIDDEN_FAIL = CheckResult(
    "t::test_c", "secret_corner", 2, 2, True, "failed", "CheckFailed",
    "wrong\nFalsifying example: secret_input(shape=(7, 1, 1))",
)  # fmt: skip
HIDDEN_PASS = CheckResult("t::test_d", "secret_size", 2, 1, True, "passed")
TODO = [
    CheckResult(f"t::{n}", n, 3, 2, h, "failed", "NotImplementedError", "Task 3: rotate it")
    for n, h in (("one", False), ("two", False), ("three", True))
]


def test_student_feedback_hides_hidden_checks_and_temporary_paths():
    grade = Grade("alice", report(PUBLIC_FAIL, PUBLIC_PASS, HIDDEN_FAIL, HIDDEN_PASS, *TODO))
    text = feedback.for_student(grade)
    assert "secret" not in text and "Falsifying" not in text and "msdlab-grade" not in text
    assert "2 hidden checks: 1 of 3 points" in text
    assert "net force 0.5 at task2.py line 3" in text and "rest_state: 0 of 2 points" in text
    task3 = text.split("## Task 3")[1].strip().splitlines()
    assert len(task3) == 2 and "Not attempted" in task3[1]  # heading and one line
    everything = feedback.for_instructor(grade)
    assert "secret_corner" in everything and "secret_input" in everything


def test_class_summary_spread_and_most_failed_over_the_whole_class(tmp_path):
    connection = gradebook_db.connect(tmp_path / "grades.db")
    for name, checks in (("a", (PUBLIC_FAIL, PUBLIC_PASS, HIDDEN_FAIL)), ("b", (PUBLIC_FAIL,))):
        result = gradebook_db.Result(name, name, gradebook_db.GRADED, [], report(*checks), "p")
        gradebook_db.record(connection, result, None)  # each in a run of its own
    failed = gradebook_db.Result("c", "c", gradebook_db.NOT_GRADED, ["timed out after 9 s"])
    gradebook_db.record(connection, failed, None)
    render.render(connection, tmp_path / "grades.csv", Terms(), tmp_path / "feedback")
    text = (tmp_path / "feedback" / "summary.md").read_text()
    assert "2 of 3 submissions graded" in text
    assert "| task2 | 7 | 1.5 | 1.5 | 0 | 3 | 0: 1, 3: 1 |" in text
    assert "- task2 rest_state: failed by 2 of 2" in text
    assert "- task2 secret_corner (hidden): failed by 1 of 2" in text


def test_gradebook_cells_are_never_formulas_and_survive_a_round_trip(tmp_path):
    book = gradebook.Gradebook()
    entry = intake.Entry("=HYPERLINK(1)", tmp_path, tmp_path)
    grade = Grade(entry.id, report(PUBLIC_FAIL, PUBLIC_PASS), ["-1 is what @you returned"])
    book.record(grade, entry, "abc", detail=True)
    path = tmp_path / "grades.csv"
    book.write(path)
    cells = [cell for row in csv.reader(path.open()) for cell in row]
    assert not any(cell.startswith(csv_files.FORMULA_STARTS) for cell in cells)
    rows = list(csv.DictReader(path.open()))
    assert rows[0]["id"] == intake.MAX_POINTS_ID and rows[0]["task2"] == "5"
    assert rows[0]["task2 rest_state"] == "2" and rows[1]["task2 pulls"] == "3"
    again = gradebook.Gradebook.load(path)
    assert again.rows["=HYPERLINK(1)"]["notes"] == "-1 is what @you returned"
    assert again.fingerprint_of("=HYPERLINK(1)") == "abc"


def test_a_failed_write_leaves_the_previous_file(tmp_path, monkeypatch):
    path = tmp_path / "grades.csv"
    book = gradebook.Gradebook()
    book.write(path)
    before = path.read_bytes()
    entry = intake.Entry("alice", tmp_path, tmp_path)
    book.record(Grade("alice", report(PUBLIC_PASS)), entry, "abc", detail=False)

    def crash(*args: object) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(OSError, match="disk full"):
        book.write(path)
    assert path.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["grades.csv"]


def test_fingerprint_follows_checks_and_submission(tmp_path):
    checks = folder_of_tasks(tmp_path / "checks")
    (checks / "test_x.py").write_text("def test(): pass\n")
    submission = folder_of_tasks(tmp_path / "sub", 1)
    first = gradebook.fingerprint(checks, submission)
    assert gradebook.fingerprint(checks, submission) == first
    (submission / "task1.py").write_text("# changed\n")
    assert gradebook.fingerprint(checks, submission) != first
    changed = gradebook.fingerprint(checks, submission)
    (checks / "test_x.py").write_text("def test(): assert True\n")
    assert gradebook.fingerprint(checks, submission) != changed


def task_points(checks: Path, task: int) -> tuple[int, int]:
    """(all, hidden) points of ``task``'s checks in ``checks``, from the points manifest."""
    manifest = checks.parent / "points.json"
    subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "--collect-only", "-p", "no:cacheprovider",
         f"--msdlab-points={manifest}", str(checks)],
        cwd=checks, check=True, capture_output=True,
    )  # fmt: skip
    counts = json.loads(manifest.read_text())["tasks"][str(task)]
    return counts["public"] + counts["hidden"], counts["hidden"]


def test_grade_command_keys_rows_by_student_resumes_and_regrades_one(tmp_path, capsys):
    checks = folder_of_tasks(tmp_path / "checks")
    for name in ("conftest.py", "test_task1.py", "test_task1_hidden.py", "reference_hidden.py"):
        shutil.copy(CHECKS / name, checks)
    alice = folder_of_tasks(tmp_path / "class" / "alice" / "assignments", 1)
    folder_of_tasks(tmp_path / "class" / "carol" / "assignments", 1)
    (tmp_path / "class" / "dave").mkdir()
    given = [str(alice), str(tmp_path / "class" / "carol"), str(tmp_path / "class" / "dave")]
    out, notes = tmp_path / "grades.csv", tmp_path / "feedback"
    common = ["--out", str(out), "--checks", str(checks), "--jobs", "2", "--call-timeout", "20"]
    assert main(["grade", *given, *common, "--feedback", str(notes)]) == 1  # dave: nothing
    printed = capsys.readouterr()
    assert "grading 2 submissions" in printed.err and "handed in ×1" in printed.out
    rows = {row["id"]: row for row in csv.DictReader(out.open())}
    assert list(rows) == [intake.MAX_POINTS_ID, "alice", "carol", "dave"]
    full, hidden = task_points(checks, 1)
    assert rows["alice"]["task1"] == rows[intake.MAX_POINTS_ID]["task1"] == str(full)
    assert rows["carol"]["task1"] == str(full) and "assignments/" not in rows["carol"]["notes"]
    assert "no task files" in rows["dave"]["notes"] and rows["alice"]["source"] == str(alice)
    assert {p.name for p in (notes / "students").iterdir()} == {"alice.md", "carol.md", "dave.md"}
    student = (notes / "students" / "alice.md").read_text()
    assert f"hidden checks: {hidden} of {hidden} points" in student and "(hidden)" not in student
    assert "particle_count_for_any_size" in (notes / "instructor" / "alice.md").read_text()
    assert f"| task1 | {full} |" in (notes / "summary.md").read_text()

    everyone = "2 of 3 submissions graded."  # dave handed in nothing
    assert everyone in (notes / "summary.md").read_text()
    assert main(["grade", *given[:2], *common, "--resume", "--feedback", str(notes)]) == 0
    assert "grading 0 submissions (2 unchanged since graded, skipped)" in capsys.readouterr().err
    assert everyone in (notes / "summary.md").read_text()

    (alice / "task1.py").write_text((alice / "task1.py").read_text() + WRONG_COUNT)
    assert main(["grade", str(alice), *common, "--resume", "--feedback", str(notes)]) == 0
    printed = capsys.readouterr()
    assert "grading 1 submission," in printed.err and "graded 1 of 1 submission " in printed.out
    rows = {row["id"]: row for row in csv.DictReader(out.open())}
    assert int(rows["alice"]["task1"]) < full and rows["carol"]["task1"] == str(full)
    assert len(rows) == 4
    summary = (notes / "summary.md").read_text()  # the whole class, alice's new grade in it
    assert (
        everyone in summary
        and f"| task1 | {full} | {(int(rows['alice']['task1']) + full) / 2:.1f} |" in summary
    )


def test_a_grader_error_is_named_and_hands_out_no_feedback(tmp_path, capsys):
    checks = folder_of_tasks(tmp_path / "checks")
    shutil.copy(CHECKS / "test_task1.py", checks)
    (checks / "test_broken.py").write_text("import no_such_module_of_the_grader\n")
    alice = folder_of_tasks(tmp_path / "class" / "alice", 1)
    notes = tmp_path / "feedback"
    (notes / "students").mkdir(parents=True)
    (notes / "students" / "alice.md").write_text("an earlier run's feedback")
    arguments = ["grade", str(alice), "--out", str(tmp_path / "grades.csv"), "--checks",
                 str(checks), "--feedback", str(notes)]  # fmt: skip
    assert main([*arguments, "--retries", "0"]) == 2
    error = capsys.readouterr().err
    assert "could not grade 1 submission (alice), the grader's failure and no fault" in error
    assert "No module named 'no_such_module_of_the_grader'" in error and "--resume" in error
    row = {row["id"]: row for row in csv.DictReader((tmp_path / "grades.csv").open())}["alice"]
    assert "grader error: the checks could not run (pytest exit 2)" in row["notes"]
    assert "no_such_module_of_the_grader" in (notes / "instructor" / "alice.md").read_text()
    assert not (notes / "students" / "alice.md").exists()


WRONG_COUNT = """
def particle_count(n: int = N) -> int:
    return n * n  # wrong on purpose
"""


def test_references_are_computed_once_per_run_and_read_back_exactly(tmp_path, monkeypatch):
    calls = []

    @reference_cache.cached
    def reference(x: float, steps: int = 3) -> float:
        calls.append(x)
        return x / 3.0 + steps

    assert reference(0.1) == reference(0.1) and len(calls) == 2  # no cache folder: no cache
    monkeypatch.setenv(reference_cache.ENV, str(tmp_path))
    first = reference(0.1)
    assert reference(0.1) == first == 0.1 / 3.0 + 3 and len(calls) == 3
    assert reference(0.1, steps=4) != first and len(calls) == 4


def test_array_references_are_read_back_bit_for_bit(tmp_path, monkeypatch):
    calls = []

    @reference_cache.cached
    def frames(scale: float) -> np.ndarray:
        calls.append(scale)
        return scale * np.array([[0.1, -0.0], [np.pi, 1e-300]])

    monkeypatch.setenv(reference_cache.ENV, str(tmp_path))
    first, again = frames(3.0), frames(3.0)
    assert len(calls) == 1 and again.dtype == first.dtype and again.shape == (2, 2)
    assert again.tobytes() == first.tobytes()  # every bit, the sign of -0.0 included


def test_a_narrow_table_shortens_names_but_keeps_the_hidden_mark():
    long_name = "steps_to_floor_for_any_start_height_and_gravity"
    checks = [CheckResult(f"t::{long_name}", long_name, 1, 2, True, "passed")]
    row = CheckReport("submission", checks).table(width=80).splitlines()[1]
    assert "…" in row and row.split("  ")[0].endswith("… (hidden)")


def test_a_message_cannot_close_the_instructors_code_block():
    message = "```\n![seen](https://example.com/t.png)\n```` and ` too"
    planted = CheckResult("t::test_x", "sign", 3, 0, False, "failed", "AssertionError", message)
    text = feedback.for_instructor(Grade("alice", report(planted)), "hand-ins/`odd`")
    saw = text.split("## What the failing checks saw")[1]
    _, inside, after = saw.split("\n`````\n")  # one fence longer than the message's ````
    assert "![seen]" in inside and "```` and ` too" in inside and not after.strip()
    assert "Handed in: `` hand-ins/`odd` ``" in text


def test_a_run_renders_its_views_once_at_its_end_over_the_whole_class(tmp_path, monkeypatch):
    """Not after every commit: that grows with the square of the class."""
    checks = tmp_path / "checks"
    checks.mkdir()
    (checks / "test_nothing.py").write_text("def test_nothing():\n    pass\n")
    class_ = [folder_of_tasks(tmp_path / "class" / name, 1) for name in ("ann", "ben", "cy")]
    renderings = []
    rendering = render.render

    def counted(connection, out, *arguments, **options):
        renderings.append(len(gradebook_db.read_records(connection)))
        return rendering(connection, out, *arguments, **options)

    monkeypatch.setattr(render, "render", counted)
    out = tmp_path / "grades.csv"
    arguments = [*map(str, class_), "--out", str(out), "--checks", str(checks), "--jobs", "2"]
    assert main(["grade", *arguments, "--isolation", "process"]) == 0
    assert renderings == [3]
    rows = {row["id"] for row in csv.DictReader(out.open(encoding="utf-8"))}
    assert rows == {"(max points)", "ann", "ben", "cy"}
