"""The processor time the checks of one task may take in ``msdlab check``, as when graded.

The grader charges a submission's code the processor time it uses, up to a budget per task
(``msdlab grade --task-timeout``, 60 s by default): an endless loop costs that once, however
busy the machine. `TaskBudget` gives the checks' own process the same budget: while a check
of task N runs (its setup, which imports the task file, and its call), the process's
processor time is charged to task N, and a timer (``ITIMER_PROF``, its own signal, apart
from the per-call wall-clock limit of `call_limit` and pytest-timeout's) stops the task's
code when the budget is used up. The check fails with `TaskStopped`, which says where the
student's code was when it was stopped (`stuck_at`; a stop that finds the checks' own code
running waits a little for the student's, `DEFERRALS`); the task's later checks are not run.

The checks' own work is charged too: on the reference answers it is about a second a task.
Works in the main thread of a POSIX process; elsewhere nothing is limited.
"""

from __future__ import annotations

import contextlib
import linecache
import signal
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType

TASK_TIMEOUT = 60.0
"""Processor seconds the checks of one task may take: the grader's budget per task."""


AGAIN = 0.05
"""Processor seconds after a stop at which the check is stopped again, should the student's
code (or a property check trying its input again) go on."""


DEFERRALS = 20
"""How many times (`AGAIN` apart) a stop that finds the checks' own code running waits for
the student's code, so that it can say where that was."""


class TaskStopped(Exception):
    """A task's code was stopped, or not run because it had been (an Exception, as pytest
    needs of what a fixture raises; the timer stops again what goes on after it, `AGAIN`)."""


def stuck_at(frame: FrameType | None, folder: Path | None) -> str:
    """Where the student's code was: 'assignments/task2.py, line 14, in spring_acceleration'
    and the line's code, for the innermost frame of ``frame``'s stack in a file of ``folder``
    ('at the top level of the file' for a module's own code); '' when no frame is."""
    if folder is None:
        return ""
    folder = Path(folder).resolve()
    while frame is not None and Path(frame.f_code.co_filename).resolve().parent != folder:
        frame = frame.f_back
    if frame is None:
        return ""
    path, line = frame.f_code.co_filename, frame.f_lineno
    name = getattr(frame.f_code, "co_qualname", frame.f_code.co_name)  # Python 3.11+
    function = "at the top level of the file" if name == "<module>" else f"in {name}"
    code = linecache.getline(path, line).strip()
    where = f"{folder.name}/{Path(path).name}, line {line}, {function}"
    return f"{where}\n    {code}" if code else where


@dataclass
class TaskBudget:
    """``seconds`` of processor time for the checks of each task (see the module docstring);
    ``folder`` holds the task files, to say where their code was stopped."""

    seconds: float
    folder: Path | None = None
    spent: dict[int, float] = field(default_factory=dict)
    stopped: dict[int, str] = field(default_factory=dict)
    """Task -> the check in which its code was stopped."""

    def left(self, task: int) -> float:
        """Processor seconds the checks of ``task`` may still take."""
        return self.seconds - self.spent.get(task, 0.0)

    def refuse_if_stopped(self, task: int) -> None:
        """Raise `TaskStopped` when ``task``'s code was stopped in an earlier check."""
        if task in self.stopped:
            raise TaskStopped(
                f"not run: task {task}'s code was stopped in check {self.stopped[task]} "
                "(see there); fix that and check again"
            )

    @contextlib.contextmanager
    def charged(self, task: int, check: str) -> Iterator[None]:
        """Charge the block's processor time to ``task``; stop it with `TaskStopped` when the
        task's budget is used up (``check`` is the check running)."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        left = max(self.left(task), 1e-3)

        deferred = []

        def stop(signum: int, frame: FrameType | None) -> None:
            signal.setitimer(signal.ITIMER_PROF, AGAIN)  # should the stop be swallowed
            where = stuck_at(frame, self.folder)
            if not where and len(deferred) < DEFERRALS:  # in the checks' own code: wait
                deferred.append(frame)
                return
            self.stopped.setdefault(task, check)
            raise TaskStopped(
                f"task {task}'s code used up the {self.seconds:g} s of processor time its "
                "checks may take (as when graded) and was stopped"
                + (f" in {where}" if where else "")
                + "\nan endless loop, or far too much work? (--task-timeout S allows more)"
            )

        previous = signal.signal(signal.SIGPROF, stop)
        signal.setitimer(signal.ITIMER_PROF, left)
        try:
            yield
        finally:
            remaining, _ = signal.setitimer(signal.ITIMER_PROF, 0)
            signal.signal(signal.SIGPROF, previous)
            self.spent[task] = self.seconds - (remaining if task not in self.stopped else 0.0)
