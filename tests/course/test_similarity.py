"""The similarity report: a planted class where one student's work was copied twice, once
with its variables renamed and once with its functions reordered, beside three honest
solutions written independently (tests/course/similarity/copies.py). The copies are
flagged, the honest solutions are not, pairs of students are ranked over all their task
files, the page stays bounded, and only the files the grader grades are read."""

from __future__ import annotations

import contextlib
import csv
import importlib.util
import itertools
import os
import re
import shutil
from pathlib import Path

import pytest
from modules import module_at

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT, TASKS
from msdlab.instructor.judging.grading import MAX_FILE_BYTES
from msdlab.instructor.outputs.csv_files import restored
from msdlab.instructor.outputs.similarity_report import IN_FULL, TABLE_ROWS


def _copies():
    """The planted class's module, beside this file."""
    return module_at(Path(__file__).parent / "similarity" / "copies.py", "msdlab_planted_copies")


copies = _copies()

COPIED = ("original", *copies.COPIES)  # the original and its two disguised copies
HONEST = copies.HONEST[1:]  # written independently of the reference and of each other
TASK_FILES = [f"task{task}.py" for task in TASKS]


@pytest.fixture(scope="module")
def planted(tmp_path_factory) -> dict[str, Path]:
    """The planted class and its report, made once: {'class': ..., 'report': ..., 'printed'}."""
    root = tmp_path_factory.mktemp("planted")
    folders = copies.write_class(root / "class")
    blank = root / "class" / "blank" / "assignments"  # handed in the template untouched
    shutil.copytree(PROJECT_ROOT / "assignments", blank)
    given = [str(folder) for folder in [*folders.values(), blank]]
    printed = root / "printed.txt"
    with printed.open("w", encoding="utf-8") as out, contextlib.redirect_stdout(out):
        assert main(["similarity", *given, "--out", str(root / "report")]) == 0
    return {"class": root / "class", "report": root / "report", "printed": printed}


def rows(report: Path) -> list[dict[str, str]]:
    with (report / "similarity.csv").open(encoding="utf-8") as file:
        return list(csv.DictReader(file))


def row_of(report: Path, first: str, second: str) -> dict[str, str]:
    (row,) = [r for r in rows(report) if {r["first"], r["second"]} == {first, second}]
    return row


def test_the_renamed_and_the_reordered_copy_are_flagged_in_every_file(planted):
    for first, second in itertools.combinations(COPIED, 2):
        row = row_of(planted["report"], first, second)
        assert row["flagged"] == "yes" and float(row["similarity"]) >= 0.9, row
        assert all(float(row[name]) >= 0.85 for name in TASK_FILES), row


def test_honest_solutions_are_within_the_documented_range(planted):
    """docs/instructor/similarity.md: honest pairs 0.00 to 0.23 over all task files, at most
    0.36 in one file, none flagged; the copies 0.92 to 1.00 over all, 0.86 at least in one."""
    honest = [r for r in rows(planted["report"]) if {r["first"], r["second"]} & set(HONEST)]
    assert len(honest) == 3 * 6 - 3  # each honest student with the 6 others, each pair once
    assert all(r["flagged"] == "no" for r in honest), honest
    assert max(float(r["similarity"]) for r in honest) <= 0.23
    assert max(float(r[name]) for r in honest for name in TASK_FILES) <= 0.36
    of_reference = [r for r in honest if {r["first"], r["second"]} & set(COPIED)]
    assert max(float(r["similarity"]) for r in of_reference) <= 0.15


def test_the_template_text_is_left_out(planted):
    """An untouched template shares nothing with anyone: the given code does not count."""
    blank = [r for r in rows(planted["report"]) if "blank" in (r["first"], r["second"])]
    assert blank and all(r["matched"] == "0" for r in blank)


def test_stdout_is_a_short_ranked_list(planted):
    printed = planted["printed"].read_text(encoding="utf-8").splitlines()
    assert printed[0] == "3 of 21 pairs of students flagged (similarity >= 0.5, over all task " \
        "files or in one)"  # fmt: skip
    assert re.fullmatch(
        r"  1\. original and renamed +1\.00  flagged  \(task1 1\.00, .*\)", printed[1]
    )
    assert len(printed) <= 12


def test_the_page_links_each_passage_to_its_twin_in_the_same_colour(planted):
    page = (planted["report"] / "similarity.html").read_text(encoding="utf-8")
    assert "3 flagged" in page and "it changes no points" in page
    assert "1. original and renamed: similarity 1.00 (flagged)" in page
    section = page.split('id="pair-1"')[1].split('id="pair-2"')[0]
    assert section.count("<pre>") == 2 * len(TASKS)  # both sides of every task file
    passages = re.findall(
        r'<a class="passage (g\d+)"(?: id="([^"]+)" title="go to its twin")? href="#([^"]+)"', page
    )
    colour_of = {anchor: colour for colour, anchor, _ in passages if anchor}
    assert len(passages) > 20
    for colour, _, target in passages:
        assert colour_of[target] == colour, target  # the twin exists and has the same colour
    colours = {colour for colour, anchor, _ in passages if anchor.startswith("p1-task4-a")}
    assert len(colours) > 1  # the passages of one file are told apart
    # the copier's renamed line and the original's, each inside a matching passage
    assert "acc = np.zeros_like(x)" in section and "a = np.zeros_like(x)" in section


def test_a_pair_sharing_every_file_ranks_above_pairs_sharing_one(tmp_path, capsys):
    """Per file, five students who each copied one whole task file would rank beside the
    pair that copied everything; over all task files, that pair is first."""
    whole = copies.write_class(tmp_path / "planted")
    folders = {}
    for student in ("original", "renamed"):
        folders[student] = shutil.copytree(whole[student], tmp_path / "class" / student)
    for task in TASKS:  # honest work, one task file taken whole from the original
        folder = tmp_path / "class" / f"took_task{task}"
        shutil.copytree(whole[HONEST[task % len(HONEST)]], folder)
        shutil.copy(whole["original"] / f"task{task}.py", folder)
        folders[folder.name] = folder
    given = [str(folder) for folder in folders.values()]
    assert main(["similarity", *given, "--out", str(tmp_path / "report")]) == 0
    ranked = rows(tmp_path / "report")
    assert {ranked[0]["first"], ranked[0]["second"]} == {"original", "renamed"}
    for task in TASKS:  # each one-file copy is still flagged, by its file
        row = row_of(tmp_path / "report", "original", f"took_task{task}")
        assert row["flagged"] == "yes" and row[f"task{task}.py"] == "1.00", row
        assert float(row["similarity"]) < float(ranked[0]["similarity"])
    assert "1. original and renamed" in capsys.readouterr().out


def test_a_class_of_30_gets_a_bounded_page_and_a_short_list(tmp_path, capsys):
    """30 students, every one a copy of another (the worst case: every pair shares code)."""
    planted = copies.write_class(tmp_path / "planted")
    given = []
    for copy, (student, folder) in itertools.product(range(5), planted.items()):
        given.append(tmp_path / "class" / f"{student}_{copy}")
        shutil.copytree(folder, given[-1])
    assert main(["similarity", *map(str, given), "--out", str(tmp_path / "report")]) == 0
    page = (tmp_path / "report" / "similarity.html").read_text(encoding="utf-8")
    assert len(page.encode()) < 1_000_000, len(page.encode())
    assert page.count('<h2 id="pair-') == IN_FULL
    assert page.count("<tr") - 1 <= TABLE_ROWS
    assert len(rows(tmp_path / "report")) == 30 * 29 // 2  # the CSV has every pair
    assert len(capsys.readouterr().out.splitlines()) <= 12


def test_a_link_is_never_followed_and_an_oversize_file_is_not_read(planted, tmp_path, capsys):
    """A task file linked to another student's would frame that student at 1.00; a task
    file the grader ignores for its size is ignored here too, and a pipe is not read."""
    original = shutil.copytree(planted["class"] / "original", tmp_path / "class" / "original")
    framed = tmp_path / "class" / "framed"
    shutil.copytree(planted["class"] / "honest_loops" / "assignments", framed)
    (framed / "task2.py").unlink()
    os.symlink(original / "assignments" / "task2.py", framed / "task2.py")
    (framed / "task3.py").write_text("x = 1\n" * (MAX_FILE_BYTES // 6 + 1), encoding="utf-8")
    (framed / "task4.py").unlink()
    os.mkfifo(framed / "task4.py")  # reading it would wait for a writer forever
    given = [str(original), str(framed)]
    assert main(["similarity", *given, "--out", str(tmp_path / "report")]) == 0
    printed = capsys.readouterr().out
    row = row_of(tmp_path / "report", "framed", "original")
    assert row["task2.py"] == row["task3.py"] == row["task4.py"] == "", row
    assert float(row["similarity"]) < 0.2, row
    assert "framed: task4.py was left out: not a regular file" in printed
    assert "framed: task2.py was left out: not a regular file (a link is not foll" in printed
    assert f"framed: task3.py was left out: larger than {MAX_FILE_BYTES} bytes" in printed
    page = (tmp_path / "report" / "similarity.html").read_text(encoding="utf-8")
    assert "task2.py was left out: not a regular file" in page


def test_the_csv_is_safe_to_open_in_a_spreadsheet(planted, tmp_path):
    from msdlab.instructor.commands.similarity import write_report

    formula = '=HYPERLINK("http://evil.example","click")'
    folders = {formula: planted["class"] / "original" / "assignments",
               "@SUM(A1)": planted["class"] / "renamed" / "assignments"}  # fmt: skip
    write_report(folders, tmp_path)
    (row,) = rows(tmp_path)
    assert {row["first"], row["second"]} == {"'" + formula, "'@SUM(A1)"}
    assert {restored(row["first"]), restored(row["second"])} == set(folders)
    page = (tmp_path / "similarity.html").read_text(encoding="utf-8")
    assert "=HYPERLINK(&quot;http://evil.example&quot;" in page


def test_a_missing_copydetect_is_named_with_the_install_command(planted, monkeypatch, capsys):
    found = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: None if name == "copydetect" else found(name, *a),
    )
    given = [str(planted["class"] / "original"), str(planted["class"] / "renamed")]
    assert main(["similarity", *given, "--out", str(planted["report"] / "again")]) == 2
    assert "pip install 'msdlab[grade]'" in capsys.readouterr().err


def test_a_threshold_outside_0_to_1_is_refused(planted, capsys):
    given = [str(planted["class"] / "original"), str(planted["class"] / "renamed")]
    assert main(["similarity", *given, "--threshold", "50", "--out", str(planted["report"])]) == 2
    assert "--threshold is a similarity between 0 and 1, got 50" in capsys.readouterr().err


def test_grade_with_similarity_flags_the_copy_and_gives_it_the_same_points(
    planted, tmp_path, capsys
):
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(PROJECT_ROOT / "tests" / "tasks" / name, checks)
    given = []
    for student in ("original", "renamed"):  # task 1 only, to grade fast
        given.append(tmp_path / "class" / student)
        given[-1].mkdir(parents=True)
        shutil.copy(planted["class"] / student / "assignments" / "task1.py", given[-1])
    out = tmp_path / "grades.csv"
    common = ["--checks", str(checks), "--call-timeout", "20", "--jobs", "2"]
    assert main(["grade", *map(str, given), "--out", str(out), *common, "--similarity"]) == 0
    assert "1 of 1 pairs of students flagged" in capsys.readouterr().out
    grades = {r["id"]: r for r in csv.DictReader(out.open(encoding="utf-8"))}
    assert grades["original"]["total"] == grades["renamed"]["total"] != "0"
    row = row_of(tmp_path / "similarity", "original", "renamed")
    assert row["flagged"] == "yes" and row["task1.py"] == "1.00"
