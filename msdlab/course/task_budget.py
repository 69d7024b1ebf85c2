"""The processor time each function of a task file may take in ``msdlab check``'s checks of
its task, as when graded.

The grader charges a submission's code the processor time it uses, per function of the task
file and per task, up to a budget (``msdlab grade --task-timeout``, 60 s by default): an
endless loop costs that once, however busy the machine, and only that function's later
calls fail. `TaskBudget` gives the checks' own process the same budget by sampling: while a
graded check runs (its setup, which imports the task files, and its call), a timer of its
own (``ITIMER_PROF``, apart from the per-call wall-clock limit of `call_limit` and
pytest-timeout's) ticks every `TICK` processor seconds, and each tick is charged to the
function of the student's files that the checks called into (the outermost frame in their
folder: ``DampedVerlet.step`` for a step the engine asked of it; a file's top level while it
is imported). Time spent in the checks' own code is charged to nothing. A function that has
used up its budget is stopped with `TaskStopped`, which says where the student's code was
(`stuck_at`); later in the task's checks it is stopped again at its first tick. Code that
catches the stop and goes on is stopped at the next tick by `StopIgnored`, which
``except Exception`` does not catch.

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

from .call_limit import StopIgnored

TASK_TIMEOUT = 60.0
"""Processor seconds each function may take in its task's checks: the grader's budget."""

TICK = 0.05
"""Processor seconds between two samples of where the student's code is."""


class TaskStopped(Exception):
    """A function of a task file used up its processor time and was stopped (an Exception,
    as pytest needs of what a fixture raises; should the student's code swallow it, the
    next tick raises it again as `StopIgnored`)."""


def student_frames(frame: FrameType | None, folder: Path) -> list[FrameType]:
    """The frames of ``frame``'s stack in a file of ``folder``, innermost first."""
    found = []
    while frame is not None:
        if Path(frame.f_code.co_filename).resolve().parent == folder:
            found.append(frame)
        frame = frame.f_back
    return found


def function_of(frame: FrameType) -> str:
    """'task2.py: spring_acceleration' (a method with its class; 'task2.py, at its top level'
    for a module's own code)."""
    file = Path(frame.f_code.co_filename).name
    name = getattr(frame.f_code, "co_qualname", frame.f_code.co_name)  # Python 3.11+
    return f"{file}, at its top level" if name == "<module>" else f"{file}: {name}"


def stuck_at(frame: FrameType | None, folder: Path | None) -> str:
    """Where the student's code was: 'assignments/task2.py, line 14, in spring_acceleration'
    and the line's code, for the innermost frame of ``frame``'s stack in a file of ``folder``
    ('at the top level of the file' for a module's own code); '' when no frame is."""
    if folder is None:
        return ""
    frames = student_frames(frame, Path(folder).resolve())
    if not frames:
        return ""
    inner = frames[0]
    path, line = inner.f_code.co_filename, inner.f_lineno
    name = getattr(inner.f_code, "co_qualname", inner.f_code.co_name)
    function = "at the top level of the file" if name == "<module>" else f"in {name}"
    code = linecache.getline(path, line).strip()
    where = f"{Path(folder).resolve().name}/{Path(path).name}, line {line}, {function}"
    return f"{where}\n    {code}" if code else where


@dataclass
class TaskBudget:
    """``seconds`` of processor time for each function of the task files in ``folder``, in
    each task's checks (see the module docstring)."""

    seconds: float
    folder: Path
    spent: dict[tuple[int, str], float] = field(default_factory=dict)
    stopped: dict[tuple[int, str], str] = field(default_factory=dict)
    """(task, function) -> the check in which it was first stopped."""
    said: dict[str, str] = field(default_factory=dict)
    """Check -> what its first stop said (the check fails with it, should its code or the
    check's have caught the stop)."""
    raised: dict[tuple[int, str], tuple[str, TaskStopped]] = field(default_factory=dict)
    """(task, function) -> the check in which it was last stopped, and that stop."""

    def __post_init__(self) -> None:
        self.folder = Path(self.folder).resolve()

    @contextlib.contextmanager
    def charged(self, task: int, check: str) -> Iterator[None]:
        """Charge the student's code that runs in the block to its functions in ``task``'s
        checks; stop one that has used up its budget (``check``: the check running)."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        previous = signal.signal(signal.SIGPROF, lambda _, frame: self._tick(task, check, frame))
        signal.setitimer(signal.ITIMER_PROF, TICK, TICK)
        try:
            yield
        finally:
            signal.setitimer(signal.ITIMER_PROF, 0)
            signal.signal(signal.SIGPROF, previous)

    def _tick(self, task: int, check: str, frame: FrameType | None) -> None:
        """One sample: charge it to the function the checks called into, if any; stop that
        function when its budget is used up."""
        frames = student_frames(frame, self.folder)
        if not frames:
            return
        key = (task, function_of(frames[-1]))
        self.spent[key] = self.spent.get(key, 0.0) + TICK
        if self.spent[key] < self.seconds:
            return
        in_check, earlier = self.raised.get(key, ("", None))
        if in_check == check:  # its code caught the stop and went on
            raise StopIgnored(str(earlier)) from earlier
        self.said.setdefault(check, self._stop_message(key, check, frame))
        stop = TaskStopped(self.said[check])
        self.raised[key] = (check, stop)
        raise stop

    def _stop_message(self, key: tuple[int, str], check: str, frame: FrameType | None) -> str:
        """What stopping ``key``'s function in ``check`` says: where it was, or, after its
        first check, where to look."""
        (task, function), first = key, self.stopped.setdefault(key, check)
        if first != check:
            return (
                f"{function} had used up its processor time in task {task}'s checks in check "
                f"{first} and was stopped again (see there)"
            )
        return (
            f"{function} used up the {self.seconds:g} s of processor time it may take in task "
            f"{task}'s checks (as when graded) and was stopped in {stuck_at(frame, self.folder)}"
            "\nan endless loop, or far too much work? (--task-timeout S allows more)"
        )
