"""What the student release ships, and the solution text that must not be in it.

One place for the rules that ``msdlab release`` builds the bundle by and that the
course's tests check the repository against:

- `shipped_files`: the files of a course folder that go to students: the engine
  (``msdlab/``), the templates (``assignments/``), the notebooks and the public
  checks (``tests/tasks/`` without the instructor-only ``*_hidden.py`` files,
  which hold the hidden checks and the references they compare with).
- `solution_lines`: the code lines of the solution blocks of ``solutions/``
  that are long enough to give an answer away.
- `solution_leaks`: where such a line appears verbatim in some files.
"""

from __future__ import annotations

import io
import json
import tokenize
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from .templates import BEGIN, END, solution_files

SHIPPED = ("msdlab", "assignments", "notebooks", "tests/tasks")
"""Folders of a course checkout that go to students (with `is_shipped` deciding per file)."""

INSTRUCTOR_ONLY = "*_hidden.py"
"""Files of ``tests/tasks`` that stay with the instructor: hidden checks and their references."""

INSTRUCTOR_PACKAGE = "instructor"
"""The part of ``msdlab/`` that stays with the instructor: grading, sandbox, release, templates."""

NOT_SHIPPED_PARTS = ("__pycache__", ".ipynb_checkpoints", ".pytest_cache")
"""Folders that are build or editor by-products, never shipped."""

NOT_SHIPPED_SUFFIXES = (".pyc", ".pyo", ".so", ".pyd")
"""Compiled by-products, never shipped (the engine compiles its kernel where it runs)."""

MIN_LINE_LENGTH = 25
"""Solution lines shorter than this (stripped) are too generic to give an answer away."""


@dataclass(frozen=True)
class Leak:
    """A solution line found verbatim in a file, at a line of `readable_lines` (the file's
    own line for code and text; for a notebook, counted over its cells and outputs)."""

    path: Path
    line_number: int
    line: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line_number}: {self.line}"


def is_shipped(relative: PurePosixPath | str) -> bool:
    """Whether a file, given by its path relative to the course folder, goes to students."""
    path = PurePosixPath(relative)
    if any(part in NOT_SHIPPED_PARTS for part in path.parts) or path.suffix in NOT_SHIPPED_SUFFIXES:
        return False
    top = path.parts[0] if path.parts else ""
    if top == "msdlab":
        return len(path.parts) > 1 and path.parts[1] != INSTRUCTOR_PACKAGE
    if (
        top == "notebooks"
    ):  # the notebooks themselves; their sources and build script need solutions/
        return len(path.parts) == 2 and path.suffix == ".ipynb"
    if top == "assignments":
        return len(path.parts) == 2 and path.suffix == ".py"
    if path.parent == PurePosixPath("tests/tasks"):
        return path.suffix == ".py" and not path.match(INSTRUCTOR_ONLY)
    return False


def shipped_files(root: Path) -> list[Path]:
    """Every file of the course folder ``root`` that goes to students, sorted."""
    root = Path(root)
    found = []
    for folder in SHIPPED:
        start = root / folder
        if not start.is_dir():
            continue
        for path in start.rglob("*"):
            if path.is_file() and is_shipped(path.relative_to(root).as_posix()):
                found.append(path)
    return sorted(found)


def solution_lines(solutions: Path, min_length: int = MIN_LINE_LENGTH) -> set[str]:
    """The code lines of every solution block of ``solutions/taskN.py``, stripped, without
    comments (whole-line or trailing), that are at least ``min_length`` characters long."""
    lines: set[str] = set()
    for path in solution_files(Path(solutions)):
        source = path.read_text(encoding="utf-8")
        comments = _comment_columns(source)
        inside = False
        for number, line in enumerate(source.splitlines(), start=1):
            stripped = line.strip()
            if stripped == BEGIN:
                inside = True
            elif stripped == END:
                inside = False
            elif inside:
                code = line[: comments.get(number, len(line))].strip()
                if len(code) >= min_length:
                    lines.add(code)
    return lines


def readable_lines(path: Path) -> list[str]:
    """The lines a reader of ``path`` sees: a notebook's cell sources and text outputs,
    a text file's lines, nothing for a binary file."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError:
        return []
    if Path(path).suffix != ".ipynb":
        return text.splitlines()
    try:
        cells = json.loads(text).get("cells", [])
    except (ValueError, AttributeError):
        return text.splitlines()
    lines: list[str] = []
    for cell in cells:
        lines += _joined(cell.get("source", "")).splitlines()
        for output in cell.get("outputs", []):
            lines += _joined(output.get("text", "")).splitlines()
            for value in output.get("data", {}).values():
                if isinstance(value, (str, list)):
                    lines += _joined(value).splitlines()
    return lines


def solution_leaks(files: Iterable[Path], lines: set[str]) -> list[Leak]:
    """Every place where one of ``lines`` appears verbatim in ``files``."""
    leaks = []
    for path in files:
        for number, text in enumerate(readable_lines(path), start=1):
            leaks += [Leak(Path(path), number, line) for line in sorted(lines) if line in text]
    return leaks


def _comment_columns(source: str) -> dict[int, int]:
    """Line number -> column where a comment starts (a ``#`` inside a string is no comment)."""
    tokens = tokenize.generate_tokens(io.StringIO(source).readline)
    return {token.start[0]: token.start[1] for token in tokens if token.type == tokenize.COMMENT}


def _joined(value: str | list[str]) -> str:
    return value if isinstance(value, str) else "".join(value)
