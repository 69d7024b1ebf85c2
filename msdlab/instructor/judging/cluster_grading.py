"""Grading a class's submissions on a Dask distributed cluster.

Each submission is one task running `grading.grade` on a worker: the same
function, workspace, judge, sandbox and limits as the local pool, so the rows
are the same. The submission folders and the checks must be at the same paths
on every worker (a shared file system). A worker that dies mid-submission (out
of memory, killed, its machine lost) makes the scheduler run that submission
again on another worker; if it keeps killing workers, its row says so instead
of being lost (`analysis.cluster.run_all`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ...analysis import cluster
from . import grading


def grade_all_on_cluster(
    submissions: Sequence[grading.Submission],
    checks: Path,
    address: str,
    *,
    progress: Callable[[grading.Grade, int, int], None] | None = None,
    retries: int = 1,
    **options: Any,
) -> list[grading.Grade]:
    """Grade ``submissions`` on the workers of the Dask scheduler at ``address``.

    Returns the grades in the order of ``submissions``; ``progress(grade, done, count)``
    is called as each one ends, as `grading.grade_all` does; ``options`` go to
    `grading.grade` (limits, isolation, allowed delegation).
    """
    calls = [((submission, checks), options) for submission in submissions]
    done = grading.rows(submissions, progress)
    outcomes = cluster.run_all(
        address, grading.grade, calls, label="grading", retries=retries, done=done
    )
    return [grading.as_grade(s, outcome) for s, outcome in zip(submissions, outcomes)]
