"""Grading a class's submissions on a Dask distributed cluster.

Each submission is one task running `grading.grade` on a worker: the same
function, workspace, judge, sandbox and limits as the local pool, so the rows
are the same. The submission folders and the checks must be at the same paths
on every worker (a shared file system). A worker that dies mid-submission (out
of memory, killed, its machine lost) makes the scheduler run that submission
again on another worker; if it keeps killing workers, its row says so instead
of being lost.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from . import grading


def grade_all_on_cluster(
    submissions: Sequence[grading.Submission],
    checks: Path,
    client: Any,
    *,
    progress: Callable[[grading.Grade, int, int], None] | None = None,
    **options: Any,
) -> list[grading.Grade]:
    """Grade ``submissions`` on the workers of ``client`` (a `dask.distributed.Client`).

    Returns the grades in the order of ``submissions``; ``progress(grade, done, count)``
    is called as each one ends, as `grading.grade_all` does; ``options`` go to
    `grading.grade` (limits, isolation, allowed delegation).
    """
    from dask.distributed import as_completed

    run = uuid.uuid4().hex[:8]
    futures = [
        client.submit(grading.grade, submission, checks, key=f"grade-{run}-{i}", **options)
        for i, submission in enumerate(submissions)
    ]
    position = {future.key: i for i, future in enumerate(futures)}
    grades: list[grading.Grade | None] = [None] * len(submissions)
    for done, future in enumerate(as_completed(futures), start=1):
        i = position[future.key]
        try:
            result = future.result()
        except Exception as error:  # e.g. KilledWorker: it took down every worker it ran on
            reason = f"not graded: the cluster lost it ({type(error).__name__}: {error})"
            result = grading.Grade(submissions[i].name, None, [reason])
        grades[i] = result
        if progress is not None:
            progress(result, done, len(submissions))
    return [grade for grade in grades if grade is not None]
