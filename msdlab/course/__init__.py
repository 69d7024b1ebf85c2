"""The course around the engine: staged tasks, their templates, and the checks that grade them.

- `templates`: make the student templates (``assignments/``) from the reference
  solutions (``solutions/``) by replacing each marked solution block.
- `loader`: load the task modules of a submission (a folder laid out like ``assignments/``).
- `feedback`: the physics messages of failing checks.
- `oracles`: what the public checks compare with besides the engine (the template's loop,
  energies, engine-made variants of typical mistakes); no answers.
- `release_rules`: which files ship to students, and the solution lines none may contain.
- `report`: the machine-readable result of a check run, and its text table.
- `pytest_plugin`: ``--impl``, the task fixtures, markers, points and the JSON report.
"""

from pathlib import Path

import msdlab

PROJECT_ROOT = Path(msdlab.__file__).resolve().parents[1]
"""The folder holding ``msdlab/`` and, in a course checkout, ``solutions/``, ``assignments/``,
``tests/tasks/``."""

TASKS = (1, 2, 3, 4, 5)
"""The task numbers of the course."""
