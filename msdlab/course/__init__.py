"""What students use of the course: loading their task files, running the checks, feedback.

(What only instructors use, grading, the sandbox, the release and the templates' maker,
is `msdlab.instructor`, which the student bundle does not contain.)

- `loader`: load the task modules of a submission (a folder laid out like ``assignments/``).
- `feedback`: the physics messages of failing checks.
- `failure`: a failure in the course's words: the line of the task file that raised, the
  input a property check failed on.
- `oracles`: what the public checks compare with besides the engine (the template's loop,
  energies, engine-made variants of typical mistakes); no answers.
- `runner`: run the checks in a fresh pytest process, the one way (``msdlab check``, the
  notebooks, ``msdlab grade``).
- `notebook`: the notebooks' helper for trying and checking a task.
- `notebook_file`: a course notebook as the repository keeps it, without outputs.
- `report`: the machine-readable result of a check run, and its text table.
- `call_limit`: the time limit on each call into a task file (``msdlab check --call-timeout``).
- `manifest`: what the checks of each task are worth, hidden ones included.
- `own_numbers`: each student's own template parameters, derived from their roster id.
- `pytest_plugin`: ``--impl``, the task fixtures, markers, points and the JSON report.
"""

from pathlib import Path

import msdlab

PROJECT_ROOT = Path(msdlab.__file__).resolve().parents[1]
"""The folder holding ``msdlab/`` and, in a course checkout, ``solutions/``, ``assignments/``,
``tests/tasks/``."""

TASKS = (1, 2, 3, 4, 5)
"""The task numbers of the course."""
