"""The similarity report: a planted class where one student's work was copied twice, once
with its variables renamed and once with its functions reordered, beside two honest
solutions written independently (tests/course/similarity/copies.py). The copies are
flagged, the honest solutions are not, and grading gives the copies the same points."""

from __future__ import annotations

import csv
import importlib.util
import itertools
import shutil
from pathlib import Path

import pytest
from modules import module_at

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT, TASKS


def _copies():
    """The planted class's module, beside this file."""
    return module_at(Path(__file__).parent / "similarity" / "copies.py", "msdlab_planted_copies")


copies = _copies()

COPIED = ("original", *copies.COPIES)  # the original and its two disguised copies


@pytest.fixture(scope="module")
def planted(tmp_path_factory) -> dict[str, Path]:
    """The planted class and its report, made once: {'class': ..., 'report': ...}."""
    root = tmp_path_factory.mktemp("planted")
    folders = copies.write_class(root / "class")
    blank = root / "class" / "blank" / "assignments"  # handed in the template untouched
    shutil.copytree(PROJECT_ROOT / "assignments", blank)
    given = [str(folder) for folder in [*folders.values(), blank]]
    assert main(["similarity", *given, "--out", str(root / "report")]) == 0
    return {"class": root / "class", "report": root / "report"}


def rows(report: Path) -> list[dict[str, str]]:
    with (report / "similarity.csv").open(encoding="utf-8") as file:
        return list(csv.DictReader(file))


def row_of(report: Path, task_file: str, first: str, second: str) -> dict[str, str]:
    (row,) = [
        r
        for r in rows(report)
        if r["task_file"] == task_file and {r["first"], r["second"]} == {first, second}
    ]
    return row


@pytest.mark.parametrize("task", TASKS)
def test_the_renamed_and_the_reordered_copy_are_flagged(planted, task):
    for first, second in itertools.combinations(COPIED, 2):
        row = row_of(planted["report"], f"task{task}.py", first, second)
        assert row["flagged"] == "yes" and float(row["similarity"]) >= 0.85, row


def test_honest_solutions_are_not_flagged(planted):
    honest = [
        r for r in rows(planted["report"]) if {r["first"], r["second"]} & set(copies.HONEST[1:])
    ]
    assert len(honest) == 5 * (5 + 4)  # per task: each honest student with the 5 others
    assert all(r["flagged"] == "no" and float(r["similarity"]) < 0.3 for r in honest), honest


def test_the_template_text_is_left_out(planted):
    """An untouched template shares nothing with anyone: the given code does not count."""
    blank = [r for r in rows(planted["report"]) if "blank" in (r["first"], r["second"])]
    assert blank and all(r["matched"] == "0" for r in blank)


def test_the_report_ranks_pairs_and_shows_the_passages_side_by_side(planted):
    page = (planted["report"] / "similarity.html").read_text(encoding="utf-8")
    ranked = [float(r["similarity"]) for r in rows(planted["report"])]
    assert ranked == sorted(ranked, reverse=True)
    assert "15 flagged" in page and "it changes no points" in page
    assert "task2.py: original and renamed, similarity 1.00 (flagged)" in page
    # the copier's renamed line and the original's, each marked as a matching passage
    assert "<mark>" in page and "acc = np.zeros_like(x)" in page and "a = np.zeros_like(x)" in page
    section = page.split('id="pair-1"')[1].split('id="pair-2"')[0]
    assert section.count("<pre>") == 2


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
    assert "1 of 1 pairs of task files flagged" in capsys.readouterr().out
    grades = {r["id"]: r for r in csv.DictReader(out.open(encoding="utf-8"))}
    assert grades["original"]["total"] == grades["renamed"]["total"] != "0"
    assert row_of(tmp_path / "similarity", "task1.py", "original", "renamed")["flagged"] == "yes"
