"""The task notebooks in a student's bundle: templates unfinished, no solutions anywhere.

The bundle is the one ``msdlab release`` builds (``msdlab/``, ``assignments/``,
``tests/tasks/`` without the hidden checks, ``notebooks/`` without outputs, no
``solutions/``), and nothing chooses the implementation: the notebooks must find
the assignments themselves, explain each unwritten function instead of raising,
and still run to the end, check cell included. (The kernel imports the installed
msdlab, as it would after ``pip install -e .`` in the bundle.)
"""

from pathlib import Path

import nbformat
import pytest

from msdlab.course.loader import SubmissionError
from msdlab.course.notebook import Course
from msdlab.instructor import release

ROOT = Path(__file__).resolve().parents[2]
TASKS = range(1, 6)


@pytest.fixture(scope="module")
def bundle(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("release") / "bundle"
    release.build(folder, ROOT)
    assert not (folder / "solutions").exists()
    return folder


def run(path: Path) -> nbformat.NotebookNode:
    """Run a notebook in its folder with a kernel of this Python, as nbval does."""
    from jupyter_client.manager import KernelManager
    from nbclient import NotebookClient
    from nbval.kernel import CURRENT_ENV_KERNEL_NAME, NbvalKernelspecManager

    notebook = nbformat.read(path, as_version=4)
    manager = KernelManager(
        kernel_name=CURRENT_ENV_KERNEL_NAME, kernel_spec_manager=NbvalKernelspecManager()
    )
    client = NotebookClient(
        notebook, km=manager, timeout=300, resources={"metadata": {"path": str(path.parent)}}
    )
    client.execute()  # raises CellExecutionError on the first cell that fails
    return notebook


def text_of(notebook: nbformat.NotebookNode) -> str:
    return "".join(
        output.get("text", "")
        for cell in notebook.cells
        if cell.cell_type == "code"
        for output in cell.outputs
    )


@pytest.mark.parametrize("task", TASKS)
def test_task_notebook_runs_to_the_end_on_unfinished_templates(bundle, task, monkeypatch):
    monkeypatch.delenv("MSDLAB_IMPL", raising=False)
    notebook = run(bundle / "notebooks" / f"task{task}.ipynb")
    text = text_of(notebook)
    assert "task files: assignments" in text
    assert f"Task {task} is not finished:" in text
    assert f"msdlab check {task}" in text
    assert f"checks of task {task} on assignments" in text and "total: 0/" in text
    assert "Traceback" not in text


def test_the_notebook_helper_finds_the_assignments_of_a_bundle(bundle, monkeypatch):
    monkeypatch.delenv("MSDLAB_IMPL", raising=False)
    course = Course(start=bundle / "notebooks")
    assert course.label == "assignments"
    assert course.folder == (bundle / "assignments").resolve()
    with pytest.raises(SubmissionError, match="no folder of task files"):
        Course("solutions", start=bundle / "notebooks")
