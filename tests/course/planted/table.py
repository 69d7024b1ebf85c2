"""The page docs/instructor/mistakes.md: for every planted bug, the checks it fails and their cost.

Each bug of `variants.BUGS` is applied to its solution and every check of its task, public
and hidden, runs on it (in this process, as ``msdlab validate`` runs them). A task's section
records a fingerprint of what its rows follow from (the task's bugs, its solution and its
checks); ``tests/course/test_planted_table.py`` fails when one has changed since. Run from
the root of the checkout::

    python tests/course/planted/table.py          # the tasks whose inputs changed
    python tests/course/planted/table.py 5        # task 5 again, whatever changed
"""

from __future__ import annotations

import hashlib
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(Path(__file__).parent))

import variants  # noqa: E402  (beside this file, not a package)

from msdlab.course import TASKS  # noqa: E402
from msdlab.course.report import MISTAKE_SENTENCE  # noqa: E402
from msdlab.instructor import validate  # noqa: E402

PAGE = ROOT / "docs" / "instructor" / "mistakes.md"
CHECKS = ROOT / "tests" / "tasks"
SOLUTIONS = ROOT / "solutions"
SECTION = re.compile(r"^## Task (\d+)\n.*?(?=^## Task |\Z)", re.M | re.S)
FINGERPRINT = re.compile(r"<!-- inputs: (\w+) -->")
RECOGNISED = re.compile(re.escape(MISTAKE_SENTENCE).replace(r"\{\}", "(.+?)") + "$", re.M)
INTRODUCTION = """---
html_theme.sidebar_secondary.remove: true
---

# What a single mistake costs

Each row is one planted bug (`tests/course/planted/variants.py`): the reference answer with
one typical mistake, checked by every check of its task, public and hidden. It says which
checks the mistake fails, the points it costs, and the mistake the checks name when they
recognise it (the student reads it once, as `[n]`, with what each failing check saw).

A mistake costs the checks of what it gets wrong, not the checks downstream of it: a check
of something else (the measurement of the stable time step, any number of particles) passes
where the student's integrator does what their recognised mistake does. Forgetting the
damping of task 5 costs the damping's checks, not the Verlet ones.

This page is generated. Commands on this page run in the root of your clone: after
changing a task's checks, its solution or its planted bugs, make the page again with

```bash
python tests/course/planted/table.py
```

`pytest tests/course/test_planted_table.py` fails while a task's rows are out of date.
"""


def fingerprint(task: int) -> str:
    """A hash of what the rows of ``task`` follow from: its bugs, its solution, its checks."""
    digest = hashlib.sha256()
    for bug in (v for v in variants.BUGS if v.task == task):
        digest.update(repr(bug).encode())
    for path in [SOLUTIONS / f"task{task}.py", *sorted(CHECKS.glob(f"test_task{task}*.py"))]:
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def row(bug: variants.Variant, checks: list[validate.Check], total: int) -> str:
    """The table row of ``bug``: its name, the checks it fails, the points lost, its cause."""
    source = bug.apply((SOLUTIONS / f"task{bug.task}.py").read_text())
    outcomes = validate.run_source(source, bug.task, checks, seconds=120)
    failed = [c for c in checks if not outcomes[c.name].passed]
    names = ", ".join(f"`{c.name}`" + (" (hidden)" if c.hidden else "") for c in failed) or "none"
    named = sorted({m for c in failed for m in RECOGNISED.findall(outcomes[c.name].message)})
    cause = "; ".join(named) or "(no recognised mistake)"
    lost = sum(c.points for c in failed)
    return f"| {bug.name} | {names} | {lost} of {total} | {_cell(cause)} |"


def section(task: int) -> str:
    """The section of ``task``: heading, fingerprint and one row per planted bug."""
    checks = validate.collect_checks(CHECKS, task)
    total = sum(c.points for c in checks)
    lines = [
        f"## Task {task}",
        "",
        f"<!-- inputs: {fingerprint(task)} -->",
        "",
        f"{total} points in {len(checks)} checks.",
        "",
        "| mistake | checks it fails | points lost | named as |",
        "| --- | --- | --- | --- |",
        *(row(bug, checks, total) for bug in variants.BUGS if bug.task == task),
    ]
    return "\n".join(lines) + "\n\n"


def sections(page: str) -> dict[int, str]:
    """The task sections of the page's text, by task."""
    return {int(found[1]): found[0] for found in SECTION.finditer(page)}


def stale(page: str) -> list[int]:
    """The tasks whose section is missing or was made from other inputs."""
    found = sections(page)
    return [
        task
        for task in TASKS
        if task not in found
        or (FINGERPRINT.search(found[task]) or [None, None])[1] != fingerprint(task)
    ]


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def main(arguments: list[str]) -> int:
    from msdlab.course import delegation

    delegation.install()
    validate._hypothesis_profile()  # before the checks are imported: their settings inherit it
    page = PAGE.read_text(encoding="utf-8") if PAGE.is_file() else ""
    tasks = [int(a) for a in arguments] if arguments else stale(page)
    found = sections(page)
    for task in tasks:  # the page is written after each task: an interrupted run keeps them
        print(f"task {task}: running every check on each planted bug ...", flush=True)
        found[task] = section(task)
        text = INTRODUCTION + "\n" + "".join(found[t] for t in TASKS if t in found)
        PAGE.write_text(text.rstrip("\n") + "\n", encoding="utf-8")
    print(f"{PAGE}: tasks {tasks or 'none'} written")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
