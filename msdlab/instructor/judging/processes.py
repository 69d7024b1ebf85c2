"""The processes a grading run started, found and ended through ``/proc`` (Linux).

A judge starts its sandboxes in sessions of their own, so killing the judge's process
group leaves them running; `kill_tree` ends a process with every descendant it has.
`cpu_of` is the processor time some processes have used; `ProcessorClock` reads it for
the same processes again and again (what a submission's time budget is charged, before
and after every call into it).
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from pathlib import Path

TICKS = os.sysconf("SC_CLK_TCK")


def _stat(pid: str) -> list[str] | None:
    """The fields of ``/proc/PID/stat`` after the command's name (None if it is gone)."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return text[text.rfind(")") + 2 :].split()


def descendants(pid: int) -> list[int]:
    """``pid`` and every process below it, parents first."""
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").glob("[0-9]*"):
        fields = _stat(entry.name)
        if fields is not None:
            children.setdefault(int(fields[1]), []).append(int(entry.name))
    found, index = [pid], 0
    while index < len(found):
        found += children.get(found[index], [])
        index += 1
    return found


def kill_tree(pid: int) -> None:
    """SIGKILL ``pid``, every process below it, and their process groups."""
    for member in descendants(pid):
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(member, signal.SIGKILL)
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.kill(member, signal.SIGKILL)


def cpu_of(pids: list[int]) -> float:
    """The processor time (user and system, seconds) used so far by the processes ``pids``
    that are still running."""
    total = 0
    for pid in pids:
        fields = _stat(str(pid))
        if fields is not None:
            total += int(fields[11]) + int(fields[12])  # utime, stime
    return total / TICKS


class ProcessorClock:
    """The processor time (user and system, seconds) of a fixed set of processes, read
    through their ``/proc/PID/stat`` files held open: a reading costs one ``pread`` per
    process instead of opening a file by its path. A process that has ended (and been
    reaped) counts no more, as in `cpu_of`; a new process with its id is never read."""

    def __init__(self, pids: list[int]) -> None:
        self.pids = list(pids)
        self._files: list[int] = []
        for pid in self.pids:
            with contextlib.suppress(OSError):
                self._files.append(os.open(f"/proc/{pid}/stat", os.O_RDONLY | os.O_CLOEXEC))

    def seconds(self) -> float:
        """Processor seconds the processes still running have used so far."""
        ticks = 0
        for handle in self._files:
            try:
                text = os.pread(handle, 4096, 0)
            except OSError:  # ended: its file reads "no such process"
                continue
            fields = text[text.rfind(b")") + 2 :].split()
            ticks += int(fields[11]) + int(fields[12])  # utime, stime
        return ticks / TICKS

    def close(self) -> None:
        """Close the files (the clock reads nothing after)."""
        for handle in self._files:
            with contextlib.suppress(OSError):
                os.close(handle)
        self._files = []


class Running:
    """The judges of a grading run, by process id, so that an interrupt can end them all:
    after `stop`, a judge that registers is ended at once."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._pids: set[int] = set()
        self.stopped = False

    @contextlib.contextmanager
    def judge(self, pid: int) -> Iterator[None]:
        """Hold ``pid`` as a running judge for the ``with`` block."""
        with self._lock:
            self._pids.add(pid)
            if self.stopped:
                kill_tree(pid)
        try:
            yield
        finally:
            with self._lock:
                self._pids.discard(pid)

    def stop(self) -> None:
        """End every running judge with its sandboxes; end any judge started from now on."""
        with self._lock:
            self.stopped = True
            for pid in list(self._pids):
                kill_tree(pid)


RUNNING = Running()
"""The judges of the grading run in this process (`grading.grade_all` starts it afresh)."""
