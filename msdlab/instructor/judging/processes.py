"""The processes a grading run started, found and ended through ``/proc`` (Linux).

A judge starts its sandboxes in sessions of their own, so killing the judge's process
group leaves them running; `kill_tree` ends a process with every descendant it has.
`cpu_of` is the processor time some processes have used; `ProcessorClock` reads it for
the same processes again and again (what a submission's time budget is charged, before
and after every call into it), and their scheduling figures (``/proc/PID/schedstat``: the
time they ran and the time they were ready to run but waited for a processor), which tell
a process that was starved by the machine from one that slept or blocked.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from dataclasses import dataclass
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


def _held(paths: list[str]) -> list[int]:
    """Read-only descriptors of those of ``paths`` that can be opened."""
    handles = []
    for path in paths:
        with contextlib.suppress(OSError):
            handles.append(os.open(path, os.O_RDONLY | os.O_CLOEXEC))
    return handles


def _read_held(handle: int) -> bytes | None:
    """A held ``/proc`` file's text now (None once its process has ended)."""
    try:
        return os.pread(handle, 4096, 0)
    except OSError:  # ended: its file reads "no such process"
        return None


def scheduled(handles: list[int]) -> tuple[float, float] | None:
    """Seconds the threads whose ``schedstat`` files are ``handles`` ran, and seconds they
    were ready to run but waited for a processor (the run queue), summed; None where the
    kernel keeps no such figures (no file could be opened)."""
    if not handles:
        return None
    ran = waited = 0
    for handle in handles:
        text = _read_held(handle)
        if text is not None:
            fields = text.split()
            ran, waited = ran + int(fields[0]), waited + int(fields[1])  # nanoseconds
    return ran / 1e9, waited / 1e9


def schedstat_files(pid: int) -> list[str]:
    """The ``schedstat`` files of every thread of ``pid`` now."""
    try:
        return [f"/proc/{pid}/task/{tid}/schedstat" for tid in os.listdir(f"/proc/{pid}/task")]
    except OSError:
        return []


def held_schedule() -> list[int]:
    """The calling thread's ``schedstat`` file, held open ([] where there is none)."""
    return _held(["/proc/thread-self/schedstat"])


def waited_for_processor(pids: list[int]) -> float:
    """Seconds the threads of ``pids`` (those still running) have waited, ready to run, for a
    processor (0 where the kernel keeps no such figures)."""
    handles = _held([path for pid in pids for path in schedstat_files(pid)])
    try:
        figures = scheduled(handles)
    finally:
        for handle in handles:
            os.close(handle)
    return 0.0 if figures is None else figures[1]


@dataclass
class Remains:
    """What a judge stopped after its time had used (read before it is ended)."""

    waited: float  # seconds its processes' threads waited, ready to run, for a processor
    judge: float  # processor seconds of the judge
    sandboxes: float  # processor seconds of the processes below it


def remains(pid: int) -> Remains:
    """The figures of the judge ``pid`` and the processes below it, still running."""
    found = descendants(pid)
    return Remains(waited_for_processor(found), cpu_of(found[:1]), cpu_of(found[1:]))


@dataclass
class Judged:
    """How a judge ended: its exit status (None: ended after its time), what it printed,
    and (ended after its time) what it had used."""

    status: int | None
    printed: str
    remains: Remains | None = None


class ProcessorClock:
    """The processor time (user and system, seconds) of a fixed set of processes, read
    through their ``/proc/PID/stat`` files held open: a reading costs one ``pread`` per
    process instead of opening a file by its path. A process that has ended (and been
    reaped) counts no more, as in `cpu_of`; a new process with its id is never read.
    `scheduled` reads the same processes' threads' scheduling figures."""

    def __init__(self, pids: list[int]) -> None:
        self.pids = list(pids)
        self._files = _held([f"/proc/{pid}/stat" for pid in self.pids])
        self._schedules = _held([path for pid in self.pids for path in schedstat_files(pid)])

    def scheduled(self) -> tuple[float, float] | None:
        """Seconds the processes ran and waited for a processor so far (see `scheduled`)."""
        return scheduled(self._schedules)

    def seconds(self) -> float:
        """Processor seconds the processes still running have used so far."""
        ticks = 0
        for handle in self._files:
            text = _read_held(handle)
            if text is None:
                continue
            fields = text[text.rfind(b")") + 2 :].split()
            ticks += int(fields[11]) + int(fields[12])  # utime, stime
        return ticks / TICKS

    def close(self) -> None:
        """Close the files (the clock reads nothing after)."""
        for handle in self._files + self._schedules:
            with contextlib.suppress(OSError):
                os.close(handle)
        self._files, self._schedules = [], []


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
