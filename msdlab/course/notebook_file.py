"""A course notebook as the course's repository keeps it: cells without outputs.

``notebooks/build.py`` writes each notebook in this form, marked in its metadata with
its own file name (``"msdlab": {"save_outputs": false, "file": "task2.ipynb"}``).
msdlab's Jupyter server extension writes a marked notebook in the same form whenever
Jupyter saves it under that name (`as_kept`), so running it in a checkout leaves the file
as git has it; saved under another name (a copy to keep one's outputs), it drops the mark.
The student release marks its notebooks to keep their outputs
(``"msdlab": {"save_outputs": true, "file": "task2.ipynb"}``, `for_students`), as in any
Jupyter. Every marked notebook is saved with the language described as it ships
(`language_as_shipped`): a kernel adds the version of the Python that runs it, which would
change the file on its first save and differs from machine to machine.
"""

from __future__ import annotations

import json
from typing import Any

# The notebook metadata build.py writes: the kernel ``python3`` that ipykernel installs in
# every environment with JupyterLab, named as ipykernel names it, so that JupyterLab opens a
# notebook on it without asking and does not rename it when it saves; the language as the
# kernel describes it, but for the version of this machine's Python.
METADATA: dict[str, Any] = {
    "kernelspec": {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"},
    "language_info": {
        "codemirror_mode": {"name": "ipython", "version": 3},
        "file_extension": ".py",
        "mimetype": "text/x-python",
        "name": "python",
        "nbconvert_exporter": "python",
        "pygments_lexer": "ipython3",
    },
}


def mark(name: str) -> dict[str, Any]:
    """The metadata marking a notebook to be kept without outputs as the file ``name``."""
    return {"msdlab": {"save_outputs": False, "file": name}}


def marked_name(notebook: dict[str, Any]) -> str | None:
    """The file name ``notebook`` (as JSON) is marked to be kept as; None if unmarked."""
    found = notebook.get("metadata", {}).get("msdlab", {})
    return found.get("file") if found.get("save_outputs") is False else None


def as_kept(notebook: dict[str, Any], name: str) -> None:
    """Reduce ``notebook`` (as JSON, in place) to its kept form as the file ``name``: the
    cells' sources and ids, no outputs, execution counts or cell metadata, and build.py's
    metadata with the mark."""
    notebook["metadata"] = {**METADATA, **mark(name)}
    for cell in notebook["cells"]:
        cell["metadata"] = {}
        if cell["cell_type"] == "code":
            cell["outputs"] = []
            cell["execution_count"] = None


def for_students(notebook: dict[str, Any], name: str) -> None:
    """Mark ``notebook`` (as JSON, in place) as the students' copy of the course notebook
    ``name``: saved with its outputs, and with the language described as it ships."""
    notebook.setdefault("metadata", {})["msdlab"] = {"save_outputs": True, "file": name}


def is_marked(notebook: dict[str, Any]) -> bool:
    """Whether ``notebook`` (as JSON) is a course notebook: the checkout's or the students'."""
    return isinstance(notebook.get("metadata", {}).get("msdlab"), dict)


def language_as_shipped(notebook: dict[str, Any]) -> None:
    """The notebook's language described as the course ships it (in place): a Python kernel's
    description without the version of the Python that ran it; another language is left."""
    metadata = notebook.get("metadata", {})
    if (metadata.get("language_info") or {}).get("name") == METADATA["language_info"]["name"]:
        metadata["language_info"] = json.loads(json.dumps(METADATA["language_info"]))


def unmarked(notebook: dict[str, Any]) -> None:
    """Drop the mark from ``notebook`` (in place): Jupyter then saves its outputs."""
    notebook.get("metadata", {}).pop("msdlab", None)
