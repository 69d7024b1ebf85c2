"""The task notebooks' text names the stiffness the task files use: an adapted course whose
``solutions/taskN.py`` has another ``STIFFNESS`` finds out here which sentence to change."""

import ast
import re
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[2]
STATED = re.compile(r"\$k = ([0-9.]+)\$")  # "$k = 0.5$" in a markdown cell


def stiffness_of(task: int) -> float | None:
    """``STIFFNESS`` of ``solutions/taskN.py`` (None where it has none)."""
    tree = ast.parse((ROOT / "solutions" / f"task{task}.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and [getattr(t, "id", "") for t in node.targets] == [
            "STIFFNESS"
        ]:
            return float(ast.literal_eval(node.value))
    return None


@pytest.mark.parametrize("task", [1, 2, 3, 4, 5])
def test_the_notebook_states_the_stiffness_of_the_task_file(task):
    notebook = nbformat.read(ROOT / "notebooks" / f"task{task}.ipynb", as_version=4)
    stated = [
        float(value)
        for cell in notebook.cells
        if cell.cell_type == "markdown"
        for value in STATED.findall(cell.source)
    ]
    stiffness = stiffness_of(task)
    wrong = [value for value in stated if value != stiffness]
    assert not wrong, (
        f"notebooks/src/task{task}.py says k = {wrong[0]:g}, but solutions/task{task}.py has "
        f"STIFFNESS = {stiffness}: change that text, then run python notebooks/build.py"
    )
