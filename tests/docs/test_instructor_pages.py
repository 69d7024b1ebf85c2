"""The instructor's and the student's pages say what the code does, each thing in one place."""

from __future__ import annotations

import re
import shlex
import zipfile
from pathlib import Path

import pytest

from msdlab.cli import build_parser
from msdlab.instructor import intake
from msdlab.instructor.judging import gradescope

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
INSTRUCTOR = sorted((DOCS / "instructor").glob("*.md"))


def blocks(page: Path, language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", page.read_text(encoding="utf-8"), re.S)


def msdlab_commands(page: Path) -> list[str]:
    """The ``msdlab ...`` commands of a page's bash blocks (a line ending in ``\\`` goes on
    in the next), without their comments."""
    joined = (block.replace("\\\n", " ") for block in blocks(page, "bash"))
    lines = [line for block in joined for line in block.splitlines()]
    return [line.split("  #")[0].strip() for line in lines if line.startswith("msdlab ")]


@pytest.mark.parametrize("page", INSTRUCTOR, ids=lambda page: page.name)
def test_every_msdlab_command_of_a_page_is_accepted(page):
    parser = build_parser()
    for command in msdlab_commands(page):
        try:
            parser.parse_args(shlex.split(command)[1:])
        except SystemExit:
            pytest.fail(f"{page.name}: msdlab does not accept `{command}`")


def test_the_running_a_course_page_is_in_order_and_its_roster_reads_as_written(tmp_path):
    page = DOCS / "instructor" / "course.md"
    commands = [command.split()[1] for command in msdlab_commands(page)]
    assert commands.index("release") < commands.index("grade")
    (roster_text,) = [block for block in blocks(page, "text") if block.startswith("id,")]
    for row in roster_text.splitlines()[1:]:
        path = tmp_path / row.split(",")[1]
        if path.suffix == ".zip":
            with zipfile.ZipFile(path, "w") as archive:
                archive.writestr("task1.py", "")
        else:
            path.mkdir(parents=True)
            (path / "task1.py").write_text("")
    (tmp_path / "roster.csv").write_text(roster_text)
    ids = [entry.id for entry in intake.from_roster(tmp_path / "roster.csv").entries]
    assert ids == ["alice", "bob", "carol"]


def test_the_gradescope_page_says_where_each_file_of_the_zip_goes(tmp_path):
    """Gradescope unpacks the zip into /autograder/source/, where the autograder reads it."""
    checks = tmp_path / "checks"
    checks.mkdir()
    (checks / "test_task1.py").write_text("def test_nothing():\n    pass\n")
    gradescope.build(tmp_path / "autograder.zip", ROOT, checks, gradescope.Settings())
    with zipfile.ZipFile(tmp_path / "autograder.zip") as archive:
        top = {name.split("/")[0] + ("/" if "/" in name else "") for name in archive.namelist()}
    page = (DOCS / "instructor" / "gradescope.md").read_text(encoding="utf-8")
    for name in sorted(top):
        assert f"/autograder/source/{name}" in page, name


def titles() -> dict[str, Path]:
    pages = [page for page in DOCS.rglob("*.md") if "_build" not in page.parts]
    return {page.read_text(encoding="utf-8").splitlines()[0][2:]: page for page in pages}


@pytest.mark.parametrize("page", INSTRUCTOR, ids=lambda page: page.name)
def test_no_section_repeats_another_pages_subject(page):
    """A section titled like another page (clusters' "Grading time") repeats that page."""
    headings = re.findall(r"^#{2,} (.+)$", page.read_text(encoding="utf-8"), re.M)
    repeated = [h for h in headings if h in titles() and titles()[h] != page]
    assert not repeated, f"{page.name}: {repeated} have pages of their own"


def test_the_student_pages_leave_the_measurements_to_the_performance_page():
    for page in sorted((DOCS / "student").glob("*.md")):
        text = page.read_text(encoding="utf-8")
        assert "load average" not in text and "frames / s" not in text, page.name
    assert "frames / s" in (DOCS / "engine" / "performance.md").read_text(encoding="utf-8")
