"""An instructor's term: a class with a late, an extended, a copied and an overridden
submission, graded with a due date and the similarity report, kept through --resume and
a one-student regrade, exported to Canvas and read back as Canvas reads a gradebook
import; every command as typed in the instructor's folder (the `shell` of the journey
tests)."""

from __future__ import annotations

import csv
import os
import shutil
from datetime import datetime, timezone
from pathlib import Path

from modules import module_at

from msdlab.course import PROJECT_ROOT
from msdlab.instructor.judging import sandbox

SOLUTIONS = PROJECT_ROOT / "solutions"
CHECKS = PROJECT_ROOT / "tests" / "tasks"
COPIES = PROJECT_ROOT / "tests" / "course" / "similarity" / "copies.py"
WRONG_COUNT = """
def particle_count(n: int = N) -> int:
    return n * n  # wrong on purpose
"""
# each submission in its bubblewrap sandbox, where there is one
ISOLATION = "" if sandbox.isolation_problem() is None else " --isolation process"
HANDED_IN = {  # UTC; due 2027-03-01 23:59 in Berlin is 22:59 UTC
    "alice": datetime(2027, 3, 1, 20, 0, tzinfo=timezone.utc),
    "bob": datetime(2027, 3, 2, 23, 30, tzinfo=timezone.utc),  # 24 h 31 min late: 2 days
    "carol": datetime(2027, 3, 3, 12, 0, tzinfo=timezone.utc),  # late, but extended
    "dave": datetime(2027, 3, 1, 21, 0, tzinfo=timezone.utc),
    "erin": datetime(2027, 3, 1, 22, 0, tzinfo=timezone.utc),  # bob's work, names changed
}


def planted_copies():
    """The similarity tests' planted class: honest answers and disguised copies."""
    return module_at(COPIES, "msdlab_planted_copies")


def handed_in_class(root: Path) -> list[Path]:
    """Alice, carol and dave hand in the reference answer (dave with a bug), bob an answer
    of his own (loops), erin bob's with its variables renamed."""
    copies = planted_copies()
    own = copies.answered(1, PROJECT_ROOT / "tests" / "course" / "alternatives")
    folders = []
    for student, moment in HANDED_IN.items():
        folder = root / "class" / student / "assignments"
        folder.mkdir(parents=True)
        shutil.copy(SOLUTIONS / "task1.py", folder)
        if student in ("bob", "erin"):
            answer = own if student == "bob" else copies.renamed(own)
            (folder / "task1.py").write_text(answer, encoding="utf-8")
        if student == "dave":
            (folder / "task1.py").write_text((folder / "task1.py").read_text() + WRONG_COUNT)
        os.utime(folder / "task1.py", (moment.timestamp(), moment.timestamp()))
        folders.append(folder)
    return folders


def task1_checks(root: Path) -> Path:
    checks = root / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py", "test_task1_hidden.py", "reference_hidden.py"):
        shutil.copy(CHECKS / name, checks)
    return checks


def read_rows(path: Path) -> dict[str, dict[str, str]]:
    return {row["id"]: row for row in csv.DictReader(path.open(encoding="utf-8"))}


def read_as_canvas(path: Path) -> tuple[dict[str, float], dict[str, dict[str, float | None]]]:
    """Points possible and each student's scores, by SIS User ID, as Canvas's gradebook
    import reads them: five student columns, then assignments; a second line whose first
    cell is 'Points Possible' gives the points; every other line must name a student."""
    lines = list(csv.reader(path.open(encoding="utf-8-sig")))
    header, body = lines[0], lines[1:]
    assert header[:5] == ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"]
    assignments = header[5:]
    possible = {}
    if body and body[0][0].strip() == "Points Possible":
        possible = dict(zip(assignments, map(float, body[0][5:])))
        body = body[1:]
    scores = {}
    for line in body:
        key = line[2] or line[3] or line[1]
        assert key, f"Canvas cannot tell whose line this is: {line}"
        scores[key] = {a: float(v) if v else None for a, v in zip(assignments, line[5:])}
    return possible, scores


def test_late_extended_and_overridden_work_lasts_and_reaches_canvas(tmp_path, shell):
    folders = handed_in_class(tmp_path)
    task1_checks(tmp_path)
    out, notes = tmp_path / "grades.csv", tmp_path / "feedback"
    (tmp_path / "extensions.csv").write_text("id,extension,reason\ncarol,3d,illness\n")
    (tmp_path / "grades.adjustments.csv").write_text(
        "id,task,change,reason\ndave,1,=15,counted by hand: his grid was transposed\n"
    )
    common = (
        " --out grades.csv --feedback feedback/ --checks checks --jobs 2 --call-timeout 20"
        " --due 2027-03-01T23:59 --timezone Europe/Berlin"
        " --late-policy grace=15m,penalty=10%/day,cap=50% --extensions extensions.csv" + ISOLATION
    )
    done = shell("msdlab grade class/*/assignments --similarity" + common, tmp_path)
    assert done.status == 0 and "manual changes: 1 from" in done.output, done.output
    rows = read_rows(out)
    flagged = {
        frozenset((row["first"], row["second"])): row["flagged"]
        for row in csv.DictReader((tmp_path / "similarity" / "similarity.csv").open())
    }
    assert flagged[frozenset(("bob", "erin"))] == "yes"  # the copy, names changed
    assert flagged[frozenset(("alice", "bob"))] == "no"  # two honest answers
    assert rows["erin"]["total"] == rows["bob"]["points"]  # flagged, not docked
    full = rows["(max points)"]["task1"]
    assert rows["alice"]["total"] == full and rows["alice"]["late_penalty"] == ""
    assert rows["bob"]["late_penalty"] == str(2 * int(full) / 10).removesuffix(".0")
    assert float(rows["bob"]["total"]) == int(full) * 0.8
    assert rows["bob"]["handed_in_from"] == "file modification time"
    assert rows["carol"]["total"] == full and rows["carol"]["due"] == "2027-03-04T23:59+01:00"
    assert int(rows["dave"]["points"]) < int(full) and rows["dave"]["total"] == full
    student = (notes / "students" / "bob.md").read_text()
    assert "2 started days × 10% of" in student and "handed in 1 d 31 min late" in student
    assert student.index(f"**Total: {rows['bob']['total']} of") < student.index("## Task 1")
    assert "(your extension)" in (notes / "students" / "carol.md").read_text()
    for kind in ("students", "instructor"):
        assert "his grid was transposed" in (notes / kind / "dave.md").read_text()

    # a decision made after grading reaches the grades and feedback without regrading
    with (tmp_path / "grades.adjustments.csv").open("a") as handle:
        handle.write("alice,,+2,best report of the class\n")
    done = shell("msdlab grade class/*/assignments --resume" + common, tmp_path)
    assert done.status == 0 and "5 unchanged since graded, skipped" in done.output
    rows = read_rows(out)
    assert float(rows["alice"]["total"]) == int(full) + 2 and rows["dave"]["total"] == full
    assert "best report of the class" in (notes / "students" / "alice.md").read_text()

    # regrading one student keeps his override and everyone else's row
    dave = folders[list(HANDED_IN).index("dave")]
    os.utime(dave / "task1.py", (HANDED_IN["dave"].timestamp(),) * 2)
    assert shell("msdlab grade class/dave/assignments" + common, tmp_path).status == 0
    again = read_rows(out)
    assert again["dave"]["total"] == full and again["dave"]["adjustment"] != ""
    assert {k: again[k]["total"] for k in again} == {k: rows[k]["total"] for k in rows}

    roster = tmp_path / "roster.csv"
    roster.write_text(
        "id,folder,name,email,sis_id,section\n"
        + "".join(
            f"{s},class/{s},{s.title()} Doe,{s}@uni.example,S{i},A\n"
            for i, s in enumerate(HANDED_IN)
        )
    )
    done = shell(
        "msdlab export grades.csv --roster roster.csv --format canvas --out canvas.csv"
        " --assignment 'MSD lab 1'",
        tmp_path,
    )
    assert done.status == 0, done.output
    possible, scores = read_as_canvas(tmp_path / "canvas.csv")
    assert possible == {"MSD lab 1": float(again["(max points)"]["total"])}
    assert scores == {
        f"S{i}": {"MSD lab 1": float(again[s]["total"])} for i, s in enumerate(HANDED_IN)
    }
