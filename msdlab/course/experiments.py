"""A submission's experiments, run once: the checks that ask for the same setting share it.

Tasks 3 and 4 drop a rotated cube (``drop_rotated_cube``), 1500 steps a run, and several
checks ask for the same setting (the public check, the hidden one comparing it with the
experiment as described, the search for the cause of a failure). Each setting runs once
per submission (task module); the checks share its flatness ratio, a float copied out of
the submission's process, which no check can change for another.

The checks assume that ``drop_rotated_cube`` is a function of its arguments, as the task
asks (the template's scheme from a fixed layout, no random numbers): a submission whose
result changes from one call with the same arguments to the next is judged on its first
result for each setting. A call that fails is not kept: each check that asks runs it
again and sees the failure itself.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

from .feedback import returned


@functools.lru_cache(maxsize=64)  # per task module (one submission) and setting
def cube_ratio(
    task: Any, angle: float, axis: Sequence[float], neighbours: Sequence[int], steps: int = 0
) -> float:
    """The flatness ratio (after / before) of ``task.drop_rotated_cube(angle, axis,
    neighbours)``, with ``steps=steps`` where ``steps`` is given (> 0)."""
    if steps:
        ratio = task.drop_rotated_cube(angle, axis, neighbours, steps=steps)
    else:
        ratio = task.drop_rotated_cube(angle, axis, neighbours)
    return float(returned(ratio, "drop_rotated_cube"))
