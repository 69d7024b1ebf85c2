"""The points manifest: what the checks of each task are worth, public and hidden.

The student bundle ships only the public checks; the manifest the release writes
beside them (``tests/tasks/points.json``) lets ``msdlab check`` say how many
points the hidden checks are worth without shipping them. Layout::

    {"schema": "msdlab-points/1", "tasks": {"1": {"public": 9, "hidden": 5}, ...}}
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path

SCHEMA = "msdlab-points/1"
FILE_NAME = "points.json"


def write(path: Path, graded: Iterable[tuple[int, int, bool]]) -> None:
    """Write the manifest of checks given as (task, points, hidden)."""
    tasks: dict[str, dict[str, int]] = {}
    for task, points, hidden in graded:
        counts = tasks.setdefault(str(task), {"public": 0, "hidden": 0})
        counts["hidden" if hidden else "public"] += points
    data = {"schema": SCHEMA, "tasks": dict(sorted(tasks.items()))}
    Path(path).write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")


def hidden_points(path: Path, task: int | None = None) -> int:
    """The points of the hidden checks of ``task`` (None: all tasks); 0 without a manifest."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return 0
    if not isinstance(data, dict) or data.get("schema") != SCHEMA:
        return 0
    return sum(
        int(counts.get("hidden", 0))
        for number, counts in data.get("tasks", {}).items()
        if task is None or number == str(task)
    )


def hidden_worth(checks: Path, found: Path, task: int | None = None) -> int:
    """The points of the hidden checks of ``task``: from the manifest of the checks a run
    ``found`` (written by ``--msdlab-points``), else from the one shipped in ``checks``."""
    return max(hidden_points(found, task), hidden_points(Path(checks) / FILE_NAME, task))


def worth(path: Path) -> dict[int, int]:
    """The points of each task's checks, public and hidden, in the manifest at ``path``."""
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    if not isinstance(data, dict) or data.get("schema") != SCHEMA:
        raise ValueError(f"{path} is not a points manifest ({SCHEMA})")
    return {
        int(number): int(counts.get("public", 0)) + int(counts.get("hidden", 0))
        for number, counts in data.get("tasks", {}).items()
    }
