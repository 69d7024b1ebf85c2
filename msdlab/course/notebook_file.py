"""A course notebook as the course's repository keeps it: cells without outputs.

``notebooks/build.py`` writes each notebook in this form, marked in its metadata
(``"msdlab": {"save_outputs": false}``). msdlab's Jupyter server extension writes a
marked notebook in the same form whenever Jupyter saves it (`as_kept`), so running
it in a checkout leaves the file as git has it. The student release drops the mark
(`unmarked`): there a notebook keeps its outputs, as in any Jupyter.
"""

from __future__ import annotations

from typing import Any

# The notebook metadata build.py writes: any Python 3 kernel, no versions of this machine.
METADATA: dict[str, Any] = {
    "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
    "language_info": {"name": "python"},
}
MARK: dict[str, Any] = {"msdlab": {"save_outputs": False}}


def is_marked(notebook: dict[str, Any]) -> bool:
    """Whether ``notebook`` (as JSON) is kept without outputs."""
    return notebook.get("metadata", {}).get("msdlab", {}).get("save_outputs") is False


def as_kept(notebook: dict[str, Any]) -> None:
    """Reduce ``notebook`` (as JSON, in place) to its kept form: the cells' sources and ids,
    no outputs, execution counts or cell metadata, and build.py's metadata with the mark."""
    notebook["metadata"] = {**METADATA, **MARK}
    for cell in notebook["cells"]:
        cell["metadata"] = {}
        if cell["cell_type"] == "code":
            cell["outputs"] = []
            cell["execution_count"] = None


def unmarked(notebook: dict[str, Any]) -> None:
    """Drop the mark from ``notebook`` (in place): Jupyter then saves its outputs."""
    notebook.get("metadata", {}).pop("msdlab", None)
