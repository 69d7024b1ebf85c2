"""The engine reads at a glance: no function in it is longer than 50 lines.

The engine is the package ``msdlab.engine``, its compiled loops included, and the packages
``interaction`` and ``analysis``; a function's length runs from its ``def`` (decorators
excluded) to its last line, docstring included.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "msdlab"
ENGINE = sorted(
    [
        *PACKAGE.glob("engine/**/*.py"),
        *PACKAGE.glob("interaction/*.py"),
        *PACKAGE.glob("analysis/*.py"),
    ]
)
LONGEST = 50


def function_lengths(path: Path) -> list[tuple[str, int]]:
    """(qualified name, lines) of every function and method in the file at ``path``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found: list[tuple[str, int]] = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            name = f"{prefix}{getattr(child, 'name', '')}"
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                found.append((name, child.end_lineno - child.lineno + 1))
                visit(child, f"{name}.")
            elif isinstance(child, ast.ClassDef):
                visit(child, f"{name}.")

    visit(tree, f"{path.relative_to(PACKAGE.parent).with_suffix('')}:")
    return found


def test_the_check_sees_the_functions() -> None:
    lengths = dict(function_lengths(PACKAGE / "engine" / "simulation" / "simulation.py"))
    assert 5 < lengths["msdlab/engine/simulation/simulation:Simulation.step"] <= LONGEST
    assert PACKAGE / "engine" / "backends" / "numba" / "kernel.py" in ENGINE


def test_no_engine_function_is_longer_than_50_lines() -> None:
    lengths = [item for path in ENGINE for item in function_lengths(path)]
    longest = max(lengths, key=lambda item: item[1])
    print(f"longest: {longest[0]}, {longest[1]} lines")
    too_long = [f"{name}: {lines} lines" for name, lines in lengths if lines > LONGEST]
    assert not too_long, "\n".join(too_long)
