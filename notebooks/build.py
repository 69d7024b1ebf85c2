"""Build the notebooks from their sources: ``notebooks/src/NAME.py`` -> two notebooks.

A source is a Python file in the percent format (`msdlab.course.notebook_source`),
the numbers a student reads written as markers ``{{ name }}``. Each source makes

- ``notebooks/NAME.ipynb``, the notebook people open: no outputs, marked so that
  Jupyter saves it without them (`msdlab.course.notebook_file`), so running it in a
  checkout leaves git's copy as it is;
- ``docs/notebooks/NAME.ipynb``, the same notebook run against the reference
  solutions (nbclient, a kernel of this Python, working folder ``notebooks/``) with its
  text outputs: the documentation site shows it, and nbval compares the cells marked
  ``# NBVAL_CHECK_OUTPUT`` with it. Pictures and animations are left out so that the
  files stay small and diff cleanly: run a notebook to see them.

    python notebooks/build.py              # build and run every notebook
    python notebooks/build.py task2 tour   # only those whose name contains one of the words
    python notebooks/build.py --check      # exit 1 if a notebook is not what its source makes
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import nbformat
from nbformat import NotebookNode

from msdlab.course import notebook_source
from msdlab.course.notebook_file import METADATA, mark

HERE = Path(__file__).resolve().parent
SOURCES = HERE / "src"
ROOT = HERE.parent
RUN = ROOT / "docs" / "notebooks"  # the notebooks run, with their text outputs
TEXT_ONLY = {"text/plain"}  # output data kept in the saved notebooks


def skeleton(source: Path) -> NotebookNode:
    """The notebook of ``source`` with the course's numbers, not yet run."""
    notebook = nbformat.v4.new_notebook(metadata=METADATA)
    notebook.cells = [nbformat.from_dict(cell) for cell in notebook_source.notebook_cells(source)]
    return notebook


def execute(notebook: NotebookNode) -> None:
    """Run every cell in a fresh kernel of this Python, in ``notebooks/``; stop at an error."""
    from jupyter_client.manager import KernelManager
    from nbclient import NotebookClient
    from nbval.kernel import CURRENT_ENV_KERNEL_NAME, NbvalKernelspecManager

    manager = KernelManager(
        kernel_name=CURRENT_ENV_KERNEL_NAME, kernel_spec_manager=NbvalKernelspecManager()
    )
    NotebookClient(
        notebook,
        km=manager,
        timeout=600,
        record_timing=False,
        resources={"metadata": {"path": str(HERE)}},
    ).execute()


def keep_text(notebook: NotebookNode) -> None:
    """Drop pictures, animations and widgets from the outputs, join the pieces of text a cell
    printed (how the kernel splits them depends on timing), reset the metadata."""
    notebook.metadata = nbformat.from_dict(METADATA)
    for cell in notebook.cells:
        if cell.cell_type != "code":
            continue
        kept: list[NotebookNode] = []
        for output in cell.outputs:
            if "data" in output and not set(output["data"]) <= TEXT_ONLY:
                continue
            if str(ROOT) in str(output):
                raise ValueError(f"an output shows this machine's path {ROOT}: {output}")
            previous = kept[-1] if kept else None
            if output.output_type == "stream" and previous and previous.get("name") == output.name:
                previous.text += output.text
            else:
                kept.append(output)
        cell.outputs = kept


def kept(source: Path) -> str:
    """The text of ``notebooks/NAME.ipynb`` for ``source``: not run, marked to save no outputs."""
    notebook = skeleton(source)
    notebook.metadata.update(nbformat.from_dict(mark(f"{source.stem}.ipynb")))
    return nbformat.writes(notebook) + "\n"


def build(source: Path) -> Path:
    """Write the notebook of ``source`` to open, run it and save it with its text outputs
    for the docs; return the path of the run one."""
    (HERE / f"{source.stem}.ipynb").write_text(kept(source), encoding="utf-8")
    notebook = skeleton(source)
    execute(notebook)
    keep_text(notebook)
    RUN.mkdir(exist_ok=True)
    path = RUN / f"{source.stem}.ipynb"
    nbformat.write(notebook, path)
    return path


def stale() -> list[str]:
    """Paths (from the repository) of the notebooks that are missing, orphaned or not what
    their source makes."""
    sources = {path.stem: path for path in SOURCES.glob("*.py")}
    saved = {path for folder in (HERE, RUN) for path in folder.glob("*.ipynb")}
    wanted = {folder / f"{name}.ipynb" for folder in (HERE, RUN) for name in sources}
    wrong = saved ^ wanted
    wrong.update(path for path in saved & wanted if not _current(path, sources[path.stem]))
    return sorted(str(path.relative_to(ROOT)) for path in wrong)


def _current(path: Path, source: Path) -> bool:
    """Whether the notebook at ``path`` is what ``source`` makes: the one to open exactly
    (`kept`); the run one with the same cells (type, id, source), its outputs coming from
    running it."""
    if path.parent == HERE:
        return path.read_text(encoding="utf-8") == kept(source)
    return _shape(skeleton(source).cells) == _shape(nbformat.read(path, as_version=4).cells)


def _shape(cells: list[NotebookNode]) -> list[tuple[str, str, str]]:
    return [(cell.cell_type, cell.get("id", ""), cell.source) for cell in cells]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("words", nargs="*", help="build only notebooks whose name contains one")
    parser.add_argument(
        "--check", action="store_true", help="compare only: exit 1 if a notebook is stale"
    )
    args = parser.parse_args(argv)
    if args.check:
        paths = stale()
        for path in paths:
            print(f"{path} is not what notebooks/src/{Path(path).stem}.py makes")
        if paths:
            print("run: python notebooks/build.py")
        return 1 if paths else 0
    os.environ["MSDLAB_IMPL"] = "solutions"  # the saved outputs are those of the reference
    sources = sorted(SOURCES.glob("*.py"))
    chosen = [s for s in sources if not args.words or any(w in s.stem for w in args.words)]
    names = {source.stem for source in sources}
    for orphan in [*HERE.glob("*.ipynb"), *RUN.glob("*.ipynb")]:
        if orphan.stem not in names:
            print(f"{orphan.relative_to(ROOT)} has no source: removed")
            orphan.unlink()
    for source in chosen:
        print(f"building {build(source).relative_to(ROOT)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
