"""What ships to students holds no answer: no solution line verbatim, no instructor-only file."""

from __future__ import annotations

import ast
import json
from pathlib import Path

from msdlab.course import PROJECT_ROOT, TASKS
from msdlab.instructor.release_rules import (
    MIN_LINE_LENGTH,
    is_shipped,
    readable_lines,
    shipped_files,
    solution_leaks,
    solution_lines,
)

SOLUTIONS = PROJECT_ROOT / "solutions"


def relative(paths: list[Path], root: Path = PROJECT_ROOT) -> set[str]:
    return {path.relative_to(root).as_posix() for path in paths}


def test_no_solution_line_appears_in_a_shipped_file():
    lines = solution_lines(SOLUTIONS)
    for task in TASKS:  # every solution file gives lines to look for
        source = (SOLUTIONS / f"task{task}.py").read_text(encoding="utf-8")
        assert any(line in source for line in lines), f"no solution line found in task{task}.py"
    leaks = solution_leaks(shipped_files(PROJECT_ROOT), lines)
    assert not leaks, "solution lines in files that ship to students:\n" + "\n".join(
        str(leak) for leak in leaks
    )


def test_shipped_files_are_the_engine_templates_notebooks_and_public_checks():
    shipped = relative(shipped_files(PROJECT_ROOT))
    assert {"msdlab/__init__.py", "msdlab/course/oracles.py", "tests/tasks/conftest.py"} <= shipped
    for task in TASKS:
        assert {f"assignments/task{task}.py", f"tests/tasks/test_task{task}.py"} <= shipped
    for path in shipped:
        assert path.split("/")[0] in ("msdlab", "assignments", "notebooks", "tests"), path
        assert not path.startswith(("solutions/", "tests/course/")), path
        assert not path.endswith(("_hidden.py", ".pyc")) and "__pycache__" not in path, path
    hidden = list((PROJECT_ROOT / "tests" / "tasks").glob("*_hidden.py"))
    assert len(hidden) > len(TASKS)  # the hidden checks and their references exist, unshipped
    assert not relative(hidden) & shipped


def test_the_rules_by_path():
    for path in (
        "msdlab/engine/integrators.py",
        "msdlab/course/release_rules.py",
        "assignments/task3.py",
        "notebooks/task1.ipynb",
        "tests/tasks/test_task2.py",
        "tests/tasks/conftest.py",
    ):
        assert is_shipped(path), path
    for path in (
        "solutions/task3.py",
        "tests/tasks/test_task2_hidden.py",
        "tests/tasks/reference_hidden.py",
        "tests/course/test_invert.py",
        "tests/conftest.py",
        "msdlab/__pycache__/body.cpython-312.pyc",
        "notebooks/.ipynb_checkpoints/task1-checkpoint.ipynb",
        "notebooks/src/task1.py",
        "notebooks/build.py",
        "notebooks/conftest.py",
        "assignments/notes/task1.py",
        "README.md",
        "msdlab",
    ):
        assert not is_shipped(path), path


def test_shipped_checks_import_nothing_that_stays_behind():
    """A public check that imported an instructor-only module would fail in the release."""
    tasks = PROJECT_ROOT / "tests" / "tasks"
    behind = {p.stem for p in tasks.glob("*.py") if not is_shipped(f"tests/tasks/{p.name}")}
    assert "reference_hidden" in behind
    for path in shipped_files(PROJECT_ROOT):
        if path.suffix != ".py":
            continue
        imported = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                imported |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                imported.add(node.module.split(".")[0])
        assert not imported & behind, f"{path} imports {sorted(imported & behind)}"


def test_solution_lines_are_long_code_lines_of_solution_blocks(tmp_path):
    (tmp_path / "task1.py").write_text(
        "def given() -> int:\n"
        "    return outside_the_blocks_is_given_code()\n"
        "\n"
        "def answer(n: int) -> int:\n"
        "    ### BEGIN SOLUTION\n"
        "    # TODO: a comment line, however long it is, gives nothing away\n"
        "    short = n + 1\n"
        "    total = sum(range(n)) * short  # the trailing comment is left out\n"
        '    text = "a # in a string is no comment"\n'
        "    return total\n"
        "    ### END SOLUTION\n",
        encoding="utf-8",
    )
    (tmp_path / "notes.py").write_text("    ### BEGIN SOLUTION\n    not_a_task_file = 1\n")
    assert solution_lines(tmp_path) == {
        "total = sum(range(n)) * short",
        'text = "a # in a string is no comment"',
    }
    assert all(len(line) >= MIN_LINE_LENGTH for line in solution_lines(SOLUTIONS))


def test_leaks_are_found_in_code_and_in_notebook_cells(tmp_path):
    line = "total = sum(range(n)) * short"
    script = tmp_path / "script.py"
    script.write_text(f"def f(n, short):\n    {line} + 1\n", encoding="utf-8")
    notebook = tmp_path / "task1.ipynb"
    cells = [
        {"cell_type": "markdown", "source": ["Sum the numbers.\n"]},
        {"cell_type": "code", "source": ["n, short = 3, 1\n", f"{line}\n"], "outputs": []},
    ]
    notebook.write_text(json.dumps({"cells": cells}, indent=1), encoding="utf-8")
    clean = tmp_path / "clean.py"
    clean.write_text("total = sum(range(n))\n", encoding="utf-8")
    binary = tmp_path / "picture.png"
    binary.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe")
    assert readable_lines(notebook) == ["Sum the numbers.", "n, short = 3, 1", line]
    assert readable_lines(binary) == []
    leaks = solution_leaks([script, notebook, clean, binary], {line})
    assert [(leak.path.name, leak.line_number) for leak in leaks] == [
        ("script.py", 2),
        ("task1.ipynb", 3),
    ]
    assert str(leaks[0]) == f"{script}:2: {line}"
