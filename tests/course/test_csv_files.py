"""Every CSV file the course writes is formula-safe and reads back exactly: the grades, the
exports, similarity.csv; an id a student chose keeps its row across runs."""

from __future__ import annotations

import csv
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from msdlab.cli import main
from msdlab.instructor import intake
from msdlab.instructor.judging.grading import Grade
from msdlab.instructor.outputs import csv_files, similarity
from msdlab.instructor.points import gradebook

HOSTILE_IDS = ["'=x", "'bob", "''", "=HYPERLINK(\"http://x\",\"y\")", "@SUM(1)", "+1", "-x",
               "\tx", "\uff1dcmd", "'", "plain"]  # fmt: skip
cells = st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=12)


@given(cells)
def test_every_text_reads_back_exactly_and_is_never_a_formula(text):
    written = csv_files.neutralised(text)
    assert csv_files.restored(written) == text
    if not csv_files.NUMBER.fullmatch(written):
        assert not written.startswith(csv_files.FORMULA_STARTS)


@given(st.lists(st.lists(cells, min_size=1, max_size=4), max_size=5))
def test_a_file_reads_back_exactly(tmp_path_factory, lines):
    path = tmp_path_factory.mktemp("csv") / "lines.csv"
    csv_files.write_csv(path, lines, header=["a", "b"])
    assert csv_files.read_csv(path) == [["a", "b"], *lines]


def unsafe(path: Path) -> list[str]:
    """The cells of the CSV file at ``path`` a spreadsheet would take for a formula."""
    with path.open(newline="", encoding="utf-8") as handle:
        found = [cell for line in csv.reader(handle) for cell in line]
    return [c for c in found if c.startswith(csv_files.FORMULA_STARTS) and not
            csv_files.NUMBER.fullmatch(c)]  # fmt: skip


def test_ids_a_student_chose_keep_their_rows_across_runs_and_exports(tmp_path):
    book = gradebook.Gradebook()
    for identifier in HOSTILE_IDS:
        entry = intake.Entry(identifier, tmp_path / identifier, tmp_path)
        book.record(Grade(identifier, None, ["=1+1 is what @you wrote"]), entry, None, False)
    grades = tmp_path / "grades.csv"
    book.write(grades)
    again = gradebook.Gradebook.load(grades)
    assert sorted(again.rows) == sorted(HOSTILE_IDS)
    assert again.rows["'=x"]["notes"] == "=1+1 is what @you wrote"
    again.write(grades)
    assert sorted(gradebook.Gradebook.load(grades).rows) == sorted(HOSTILE_IDS)  # no new rows
    assert unsafe(grades) == []
    (tmp_path / "grades.adjustments.csv").write_text("id,task,change,reason\n'=x,,+1,report\n")
    out = tmp_path / "class.csv"
    assert main(["export", str(grades), "--format", "csv", "--out", str(out)]) == 0
    header, *lines = csv_files.read_csv(out)
    exported = {line[0]: dict(zip(header, line)) for line in lines}
    assert sorted(exported) == sorted(HOSTILE_IDS) and unsafe(out) == []
    assert exported["'=x"]["total"] == "1"  # its total: 0 points and the change written for it


def test_similarity_csv_writes_ids_as_text(tmp_path):
    pair = similarity.Pair(("=HYPERLINK(1)", "'bob"), (), (0, 0))
    path = tmp_path / "similarity.csv"
    similarity.write_csv([pair], path, threshold=0.5)
    (line,) = csv_files.read_csv(path)[1:]
    assert line[:2] == ["=HYPERLINK(1)", "'bob"] and unsafe(path) == []
