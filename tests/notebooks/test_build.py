"""The committed notebooks are what ``notebooks/build.py`` makes from ``notebooks/src``: the
ones people open without outputs, the run ones (docs/notebooks) with the outputs that nbval
compares."""

import importlib.util
from pathlib import Path

import nbformat
import pytest

from msdlab.course import notebook_source

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))  # to open
RUN = sorted((ROOT / "docs" / "notebooks").glob("*.ipynb"))  # run, with their outputs


def load_build():
    spec = importlib.util.spec_from_file_location("notebook_build", ROOT / "notebooks" / "build.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


build = load_build()


def test_committed_notebooks_are_built_from_their_sources():
    stale = build.stale()
    assert not stale, f"stale notebooks {stale}: run python notebooks/build.py"


def test_every_task_and_scene_has_a_notebook():
    wanted = {"00_tour", "stability", "scene_trampoline", "scene_cloth", "scene_gallery"}
    wanted |= {f"task{n}" for n in range(1, 6)}
    assert wanted <= {path.stem for path in NOTEBOOKS}
    assert {path.stem for path in RUN} == {path.stem for path in NOTEBOOKS}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_the_notebooks_people_open_hold_no_outputs_and_say_so(path):
    """So that running one in a checkout, Jupyter saving it as kept, leaves git's copy."""
    notebook = nbformat.read(path, as_version=4)
    assert notebook.metadata["msdlab"] == {"save_outputs": False, "file": path.name}
    for cell in notebook.cells:
        assert cell.metadata == {}
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, cell.source


@pytest.mark.parametrize("path", RUN, ids=lambda path: path.stem)
def test_checked_cells_hold_their_outputs(path):
    """A checked cell saved without outputs would compare nothing: a silent pass."""
    notebook = nbformat.read(path, as_version=4)
    code = [c for c in notebook.cells if c.cell_type == "code"]
    checked = [c for c in code if "NBVAL_CHECK_OUTPUT" in c.source]
    assert checked, f"{path.name} checks no output"
    for cell in checked:
        assert cell.outputs, f"{path.name}: a checked cell has no saved output:\n{cell.source}"
    for cell in code:
        assert all(output.output_type != "error" for output in cell.outputs), cell.source


@pytest.mark.parametrize("path", RUN, ids=lambda path: path.stem)
def test_saved_outputs_are_text_and_say_nothing_of_this_machine(path):
    text = path.read_text(encoding="utf-8")
    assert "image/png" not in text and "text/html" not in text
    assert str(ROOT) not in text
    assert " at 0x" not in text  # memory addresses
    notebook = nbformat.read(path, as_version=4)
    assert all("execution" not in cell.metadata for cell in notebook.cells)  # no timings


def test_percent_format_makes_markdown_and_code_cells():
    source = "# %% [markdown]\n# # Title\n#\n# Some $x$.\n\n# %%\nx = 1\n\n\n# %%\nprint(x)\n"
    cells = notebook_source.cells(source)
    assert [c["cell_type"] for c in cells] == ["markdown", "code", "code"]
    assert cells[0]["source"] == "# Title\n\nSome $x$."
    assert cells[1]["source"] == "x = 1"
    assert len({c["id"] for c in cells}) == 3


def test_cell_ids_follow_the_content_not_the_position():
    first = notebook_source.cells("# %%\na = 1\n# %%\nb = 2\n")
    inserted = notebook_source.cells("# %%\nz = 0\n# %%\na = 1\n# %%\nb = 2\n")
    assert [c["id"] for c in first] == [c["id"] for c in inserted[1:]]


@pytest.mark.parametrize(
    "source", ["x = 1\n# %%\ny = 2\n", "# %% [markdown]\nnot a comment\n"], ids=["before", "md"]
)
def test_malformed_sources_are_refused(source):
    with pytest.raises(ValueError):
        notebook_source.cells(source)


def test_saved_outputs_keep_the_text_joined_and_drop_pictures():
    cell = nbformat.v4.new_code_cell("print(1); plt.show(); print(2)")
    stream = nbformat.v4.new_output
    cell.outputs = [
        stream("stream", name="stdout", text="1\n"),
        stream("display_data", data={"image/png": "iVBO", "text/plain": "<Figure size 1x1>"}),
        stream("stream", name="stdout", text="2\n"),
    ]
    notebook = nbformat.v4.new_notebook(cells=[cell])
    build.keep_text(notebook)
    assert [dict(output) for output in cell.outputs] == [
        {"output_type": "stream", "name": "stdout", "text": "1\n2\n"}
    ]


def test_jupyterlabs_checkpoints_are_not_left_untracked():
    """Opening a notebook in JupyterLab writes notebooks/.ipynb_checkpoints/: git ignores it."""
    import shutil
    import subprocess

    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    checkpoint = "notebooks/.ipynb_checkpoints/task2-checkpoint.ipynb"
    ignored = subprocess.run(["git", "check-ignore", "-q", checkpoint], cwd=ROOT)
    assert ignored.returncode == 0, f"git would list {checkpoint} as untracked"
