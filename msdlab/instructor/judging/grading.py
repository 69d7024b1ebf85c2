"""Grading folders of submissions: each in its own workspace, judge and sandbox.

For every submission a fresh workspace gets a copy of its task files and of the
instructor's checks; a judge process (pytest with ``--sandbox``) runs the checks,
calling the submission only through `sandbox`, under a time limit, and writes a
JSON `CheckReport`. The grade is read from that report alone. Whatever happens
(a crash, a timeout, a file that does not import) the submission gets a row,
with the reason in its notes.
"""

from __future__ import annotations

import collections
import contextlib
import fcntl
import itertools
import json
import os
import queue
import resource
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from ...analysis import cluster
from ...course import TASKS, reference_cache, runner
from ...course.report import CheckReport
from ...course.runner import CheckRun
from ..intake import MAX_FILE_BYTES
from . import judges, processes
from .judges import TIMES, ForkedJudges
from .sandbox import INFRASTRUCTURE_FAILURES

FIRST_UID = 61000  # as root, sandboxes run as reserved user ids from here on
RETRY_PAUSE = 2.0  # seconds before grading again after the grader's failure, times the attempt
GRADER_ERROR = "grader error: "
"""The start of the note of a submission the grader failed to grade (no fault of its author)."""


@dataclass
class Submission:
    """A folder laid out like ``assignments/`` and the name its row gets."""

    name: str
    folder: Path


@dataclass
class Grade:
    """The outcome of grading one submission."""

    submission: str
    report: CheckReport | None
    notes: list[str] = field(default_factory=list)
    seconds: float = 0.0  # wall-clock seconds, every attempt's
    attempts: int = 1
    processor: dict[str, float] = field(default_factory=dict)
    """Processor seconds by part ("judges", "sandboxes"), every attempt's."""

    @property
    def graded(self) -> bool:
        """True if the checks ran to the end and produced a report."""
        return self.report is not None

    def points(self, task: int) -> int:
        if self.report is None:
            return 0
        return sum(c.earned for c in self.report.checks if c.task == task)

    @property
    def grader_failed(self) -> bool:
        """True if the grader itself failed (its setup or its code), not the submission."""
        return any(note.startswith(GRADER_ERROR) for note in self.notes)

    @property
    def total(self) -> int:
        return sum(self.points(task) for task in TASKS)

    def row(self) -> dict[str, object]:
        """The CSV row: submission, task1 ... task5, total, notes."""
        row: dict[str, object] = {"submission": self.submission}
        row.update({f"task{task}": self.points(task) for task in TASKS})
        row.update(total=self.total, notes="; ".join(self.notes))
        return row


def find_submissions(paths: Iterable[Path]) -> list[Submission]:
    """One `Submission` per folder, named by the folder (made unique if names repeat)."""
    submissions, seen = [], collections.Counter()
    for path in paths:
        folder = Path(path)
        if not folder.is_dir():
            raise FileNotFoundError(f"submission folder {folder} does not exist")
        name = folder.resolve().name
        seen[name] += 1
        submissions.append(Submission(name if seen[name] == 1 else f"{name}-{seen[name]}", folder))
    if not submissions:
        raise ValueError("give at least one submission folder")
    return submissions


def grade(
    submission: Submission,
    checks: Path,
    *,
    timeout: float = 600.0,
    call_timeout: float = 60.0,
    task_timeout: float = 60.0,
    memory_mb: int = 2048,
    uid: int | None = None,
    isolation: str = "namespace",
    allow_delegation: Sequence[int] = (),
    references: Path | None = None,
    server: ForkedJudges | None = None,
    own_numbers: bool = False,
) -> Grade:
    """Grade one submission with the checks in ``checks`` (see the module docstring).

    ``task_timeout`` is the time the submission's code may take for one task, all its calls
    together (`sandbox.SandboxProcess`), ``call_timeout`` the time of one call.
    As root the sandbox runs as user ``uid`` (default: one reserved for this call).
    ``isolation`` is the sandbox's level (`sandbox.ISOLATION_LEVELS`); a weaker one
    than ``namespace`` is named in the row's notes. ``references`` is a folder the
    judges share for references (`reference_cache`). With a ``server`` the judge is
    forked from it (`judges`) instead of started afresh. With ``own_numbers`` the checks
    use the numbers of the student the submission's id names (`course.own_numbers`).
    """
    if uid is None and os.geteuid() == 0:
        with reserved_uids(1) as (reserved,):
            return grade(submission, checks, timeout=timeout, call_timeout=call_timeout,
                         task_timeout=task_timeout, memory_mb=memory_mb, uid=reserved,
                         isolation=isolation, allow_delegation=allow_delegation,
                         references=references, server=server,
                         own_numbers=own_numbers)  # fmt: skip
    started = time.monotonic()
    workspace = Path(tempfile.mkdtemp(prefix="msdlab-grade-"))
    try:
        notes = _copy_submission(submission.folder, workspace / "submission")
        shutil.copytree(checks, workspace / "checks", ignore=shutil.ignore_patterns("__pycache__"))
        os.chmod(workspace, 0o700)  # the sandbox sees only its bind-mounted copy of the tasks
        report_path = workspace / "report.json"
        run = CheckRun(
            workspace / "checks",
            workspace / "submission",
            report_path,
            hidden=True,
            verbose=True,  # the last error pytest shows says why a judge gave no report
            plugins=(*runner.PLUGINS, "msdlab.instructor.judging.pytest_sandbox"),
            options=(
                "--sandbox", "--sandbox-timeout", str(call_timeout),
                "--sandbox-memory", str(memory_mb), "--sandbox-task-timeout", str(task_timeout),
                "--allow-delegation", ",".join(str(task) for task in allow_delegation),
                *([f"--student={submission.name}"] if own_numbers else []),
            ),
            workspace=workspace,
        )  # fmt: skip
        environment = runner.environment()
        environment["MSDLAB_SANDBOX_ISOLATION"] = isolation
        (workspace / "tmp").mkdir()  # the sandboxes' logs, removed with the workspace
        environment["TMPDIR"] = str(workspace / "tmp")
        if isolation != "namespace":
            notes.append(f"graded with the weaker isolation '{isolation}'")
        if uid is not None:
            environment["MSDLAB_SANDBOX_UID"] = str(uid)
        if references is not None:
            environment[reference_cache.ENV] = str(references)
        environment[TIMES] = str(workspace / "judge-times.json")
        judged = _judge(run.arguments(), workspace, environment, timeout, server)
        if uid is not None:
            _kill_user(uid)
        report = _read_report(report_path) if judged.status in (0, 1) else None
        notes += _outcome_notes(report, judged, timeout)
        if any(note.startswith(GRADER_ERROR) for note in notes):
            report = None  # the machine's failure, not the submission's
        return Grade(submission.name, report, notes, time.monotonic() - started,
                     processor=_processor_times(workspace, judged))  # fmt: skip
    except Exception as error:  # never lose a row: the reason goes to its notes
        note = f"{GRADER_ERROR}{type(error).__name__}: {error}"
        return Grade(submission.name, None, [note], time.monotonic() - started)
    finally:
        shutil.rmtree(workspace, ignore_errors=True)


def _outcome_notes(
    report: CheckReport | None, judged: processes.Judged, timeout: float
) -> list[str]:
    """The notes of a judge's outcome: the report's problems; or why there is none, blamed on
    the grader only on evidence the submission cannot produce (a sandbox ended from outside
    or kept from a processor, a judge that failed or was kept from a processor)."""
    failure = _infrastructure_failure(report)
    if failure is not None:
        return [GRADER_ERROR + failure]
    if report is not None:
        return _problems(report)
    left = judged.remains
    if left is not None and left.waited >= timeout / 2:
        return [f"{GRADER_ERROR}grading ran out of its {timeout:g} s, for {left.waited:.0f} s "
                "of which its processes were ready to run and waited for a processor"]  # fmt: skip
    if judged.status is None:
        return [f"grading timed out after {timeout:g} s"]
    return [GRADER_ERROR + _judge_failure(judged.status, judged.printed)]


def _processor_times(workspace: Path, judged: processes.Judged) -> dict[str, float]:
    """Processor seconds of the judge and its sandboxes: as the judge wrote them at its end,
    or as read before it was ended after its time ({} if neither)."""
    if judged.remains is not None:
        return {"judges": judged.remains.judge, "sandboxes": judged.remains.sandboxes}
    try:
        times = json.loads((workspace / "judge-times.json").read_text())
        return {"judges": float(times["judge"]), "sandboxes": float(times["sandboxes"])}
    except (OSError, ValueError, KeyError, TypeError):
        return {}


def grade_all(
    submissions: Sequence[Submission],
    checks: Path,
    *,
    jobs: int = 2,
    progress: Callable[[Grade, int, int], None] | None = None,
    isolation: str = "namespace",
    allow_delegation: Sequence[int] = (),
    retries: int = 2,
    **limits: float | bool,
) -> list[Grade]:
    """Grade ``submissions``, ``jobs`` at a time (threads: each judge is its own process);
    ``progress(grade, done, count)`` as each ends. A submission the grader or the machine
    failed (`Grade.grader_failed`) is graded again, up to ``retries`` times.

    On KeyboardInterrupt every running judge is ended with its sandboxes, the submissions
    not yet started are dropped, and the interrupt goes on to the caller within seconds;
    ``progress`` has been called for every submission graded before it."""
    jobs = max(1, jobs)
    slots: queue.Queue[int | None] = queue.Queue()
    server = ForkedJudges()
    processes.RUNNING = running = processes.Running()

    def one(submission: Submission) -> Grade:
        uid = slots.get()
        started, processor = time.monotonic(), collections.Counter()
        try:
            for attempt in range(1, retries + 2):
                outcome = grade(submission, checks, uid=uid, isolation=isolation,
                                allow_delegation=allow_delegation, references=references,
                                server=server, **limits)  # fmt: skip
                processor.update(outcome.processor)
                if not outcome.grader_failed or running.stopped:
                    break
                time.sleep(RETRY_PAUSE * attempt)  # let a passing overload pass
            outcome.attempts, outcome.processor = attempt, dict(processor)
            outcome.seconds = time.monotonic() - started  # every attempt's
            return outcome
        finally:
            slots.put(uid)

    calls = [((submission,), {}) for submission in submissions]
    with (
        reserved_uids(jobs) as uids,
        tempfile.TemporaryDirectory(prefix="msdlab-references-") as shared,
        ThreadPoolExecutor(max_workers=jobs) as pool,
        cluster.tally(len(calls), "grading", rows(submissions, progress)) as (grades, finished),
    ):
        references = Path(shared)
        for uid in uids:
            slots.put(uid)
        try:
            cluster.collect(pool, one, calls, range(len(calls)), finished, retries=0)
        except KeyboardInterrupt:
            pool.shutdown(wait=False, cancel_futures=True)
            running.stop()
            raise
    return [as_grade(submissions[i], grades[i]) for i in range(len(calls))]


def as_grade(submission: Submission, outcome: Grade | BaseException) -> Grade:
    """The grade, or a row that says why the grading of ``submission`` failed."""
    if isinstance(outcome, Grade):
        return outcome
    reason = f"{GRADER_ERROR}the grader lost it ({type(outcome).__name__}: {outcome})"
    return Grade(submission.name, None, [reason])


def rows(
    submissions: Sequence[Submission], progress: Callable[[Grade, int, int], None] | None
) -> cluster.Done:
    """What to do as the grading of one submission ends: ``progress(grade, done, count)``."""
    count = itertools.count(1)

    def done(index: int, outcome: Grade | BaseException) -> None:
        if progress is not None:
            progress(as_grade(submissions[index], outcome), next(count), len(submissions))

    return done


@contextlib.contextmanager
def reserved_uids(count: int) -> Iterator[list[int | None]]:
    """``count`` sandbox user ids that no other grading run on this machine holds.

    Each is held by an exclusive lock (``flock``) on a file in `lock_folder`, one folder
    for the whole machine whatever a run's ``TMPDIR``, for as long as the ``with`` block
    lasts, so two runs never share a sandbox user nor kill each other's sandboxes. The
    kernel drops a lock when its run ends, however it ends. Without root, sandboxes keep
    the grader's user: ``None``.
    """
    if os.geteuid() != 0:
        yield [None] * count
        return
    with held_uids(count, lock_folder()) as uids:
        yield uids


LOCK_FOLDERS = (Path("/run/lock/msdlab"), Path("/var/lock/msdlab"), Path("/tmp/msdlab-locks"))
"""Where the sandbox user ids are locked: the first of these that root owns (created if
missing); ``/tmp`` itself, not a run's ``TMPDIR``, is the last resort."""


def lock_folder() -> Path:
    """The machine-wide folder of the sandbox user locks (see `LOCK_FOLDERS`)."""
    for folder in LOCK_FOLDERS:
        with contextlib.suppress(OSError):
            folder.mkdir(mode=0o755, exist_ok=True)
            facts = folder.lstat()
            private = stat.S_ISDIR(facts.st_mode) and not facts.st_mode & 0o022
            if facts.st_uid == os.geteuid() and private:
                return folder
    raise OSError(f"no folder for the sandbox user locks: make one of {LOCK_FOLDERS[0]}, "
                  f"{LOCK_FOLDERS[1]} owned by root, mode 755")  # fmt: skip


@contextlib.contextmanager
def held_uids(count: int, folder: Path) -> Iterator[list[int]]:
    """``count`` user ids from `FIRST_UID` on whose lock files in ``folder`` this process
    holds (those another process holds are passed over)."""
    handles: list[int] = []
    uids, uid = [], FIRST_UID
    try:
        while len(uids) < count:
            held = _lock_all([folder / f"sandbox-{uid}.lock", *_legacy_locks(uid)])
            if held is not None:
                handles += held
                uids.append(uid)
            uid += 1
        yield uids
    finally:
        for handle in handles:
            os.close(handle)


def _legacy_locks(uid: int) -> list[Path]:
    """Where older msdlab runs lock ``uid`` (their temporary folder; ``/tmp`` by default):
    held too, so that a run of an older version on the same machine passes it over."""
    return list(dict.fromkeys(Path(p) / f"msdlab-sandbox-{uid}.lock"
                              for p in ("/tmp", tempfile.gettempdir())))  # fmt: skip


def _lock_all(paths: list[Path]) -> list[int] | None:
    """Exclusive locks on every file of ``paths`` (created if missing, never through a
    link), or None, holding none, if another process holds one of them."""
    handles = []
    for path in paths:
        try:
            handle = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
        except OSError:  # a link or a file of someone else's where no run of ours locks
            continue
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(handle)
            for held in handles:
                os.close(held)
            return None
        handles.append(handle)
    return handles


def grader_seconds() -> float:
    """Processor seconds of this process (the grader) and of its judges' server itself."""
    used = resource.getrusage(resource.RUSAGE_SELF)
    return used.ru_utime + used.ru_stime + judges.server_seconds()


def machine_time(grades: Sequence[Grade], grader: float) -> list[str]:
    """The run's processor time by part and the rows graded more than once."""
    parts = collections.Counter({"grader": grader})
    for grade in grades:
        parts.update(grade.processor)
    shares = ", ".join(f"{part} {parts[part]:.1f} s" for part in ("grader", "judges", "sandboxes"))
    lines = [f"machine time: {sum(parts.values()):.1f} s of processor time ({shares})"]
    again = [grade for grade in grades if grade.attempts > 1]
    if again:
        attempts = sum(grade.attempts for grade in again)
        lines.append(f"graded more than once: {len(again)} row{'s' * (len(again) > 1)} "
                     f"({attempts} attempts)")  # fmt: skip
    return lines


def summary(grades: Sequence[Grade], seconds: float, grader: float | None = None) -> str:
    """Count, mean points per task, failures by reason, and (given the ``grader``'s processor
    seconds) the run's machine time."""
    graded = [g for g in grades if g.graded]
    plural = "" if len(grades) == 1 else "s"
    lines = [f"graded {len(graded)} of {len(grades)} submission{plural} in {seconds:.0f} s"]
    if graded:
        possible = {t: sum(c.points for c in graded[0].report.checks if c.task == t) for t in TASKS}
        means = [
            f"task{t} {sum(g.points(t) for g in graded) / len(graded):.1f}/{possible[t]}"
            for t in TASKS
        ]
        total = sum(g.total for g in graded) / len(graded)
        lines.append(f"mean: {', '.join(means)}; total {total:.1f}/{sum(possible.values())}")
    reasons = collections.Counter(r for g in grades for r in {_reason(n) for n in g.notes})
    if reasons:
        lines.append("problems: " + ", ".join(f"{r} ×{n}" for r, n in reasons.most_common()))
    if grader is not None:
        lines += machine_time(grades, grader)
    return "\n".join(lines)


def _copy_submission(source: Path, target: Path) -> list[str]:
    """Copy the task files (regular files only, not too large); return notes on what was left."""
    notes = []
    target.mkdir(mode=0o755)
    for path in sorted(source.glob("*.py")):
        if path.is_symlink() or not path.is_file():
            notes.append(f"{path.name} is not a regular file and was ignored")
        elif path.stat().st_size > MAX_FILE_BYTES:
            notes.append(f"{path.name} is larger than {MAX_FILE_BYTES} bytes and was ignored")
        else:
            shutil.copyfile(path, target / path.name)
            (target / path.name).chmod(0o644)
    missing = [f"task{t}.py" for t in TASKS if not (target / f"task{t}.py").exists()]
    if missing:
        notes.append(f"missing: {', '.join(missing)}")
    return notes


def _judge(
    arguments: list[str],
    workspace: Path,
    environment: dict,
    timeout: float,
    server: ForkedJudges | None,
) -> processes.Judged:
    """Run the judge, forked from ``server`` or else afresh: its exit status (None: timed
    out), what it printed, and what it had used if it was ended after its time."""
    if server is not None:
        try:
            return server.run(arguments, workspace, environment, timeout)
        except (EOFError, OSError) as error:  # no server could fork: a fresh judge grades
            server.unavailable(error)
    return _run_judge(arguments, workspace, environment, timeout)


def _run_judge(
    arguments: list[str], workspace: Path, environment: dict, timeout: float
) -> processes.Judged:
    """Run a fresh judge (see `_judge`). The judge and every process below it are killed at
    the end."""
    process = subprocess.Popen(
        [sys.executable, "-m", "pytest", *arguments],
        cwd=workspace,
        env=environment,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    with processes.RUNNING.judge(process.pid):
        try:
            printed, _ = process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            left = processes.remains(process.pid)
            processes.kill_tree(process.pid)
            process.communicate()
            return processes.Judged(None, "", left)
        finally:
            processes.kill_tree(process.pid)  # and anything left behind
    return processes.Judged(process.returncode, printed.decode(errors="replace"))


def _judge_failure(status: int, printed: str) -> str:
    """Why a judge gave no report, from its exit ``status``, the last error pytest showed and
    the last line it ``printed`` (a judge runs only the grader's code: the submission's runs
    in its sandbox)."""
    lines = [line.strip() for line in printed.splitlines() if line.strip()]
    raised = [line.removeprefix("E").strip() for line in lines if line.startswith("E ")]
    tail = " | ".join(dict.fromkeys(raised[-1:] + lines[-1:]))
    tail = tail or "it printed nothing (an error before pytest started is on the grader's stderr)"
    if status in (0, 1):  # 1: some checks failed, which is a normal grade
        return f"the checks ended without a report: {tail}"
    return f"the checks could not run (pytest exit {status}): {tail}"


def _kill_user(uid: int) -> None:
    """As root, kill every process still running as ``uid`` (a sandbox left behind)."""
    if os.geteuid() != 0:
        return
    for status in Path("/proc").glob("[0-9]*/status"):
        with contextlib.suppress(OSError, ValueError, IndexError):
            fields = dict(line.split(":", 1) for line in status.read_text().splitlines())
            if int(fields["Uid"].split()[0]) == uid:
                os.kill(int(status.parent.name), signal.SIGKILL)


def _infrastructure_failure(report: CheckReport | None) -> str | None:
    """Why the checks' results are the machine's failure, not the submission's (a sandbox
    killed from outside, a call timed out while the machine gave it no time), or None."""
    for check in report.checks if report is not None else ():
        if check.exception in INFRASTRUCTURE_FAILURES:
            first = (check.message.strip().splitlines() or [check.exception])[0]
            return f"task{check.task} {check.name}: {first}"
    return None


def _read_report(path: Path) -> CheckReport | None:
    try:
        return CheckReport.read(path)
    except (OSError, ValueError, KeyError, TypeError):
        return None


_KNOWN = {
    "SubmissionTimeout": "a call timed out (endless loop?)",
    "SubmissionWaited": "a call timed out, waiting (sleeping or blocked)",
    "SubmissionCrashed": "the submission's process died",
    "MemoryError": "ran out of memory",
    "SyntaxError": "syntax error",
    "PermissionError": "tried something the sandbox forbids",
}


def _problems(report: CheckReport) -> list[str]:
    """Short notes on what went wrong beyond wrong answers, one per task and kind."""
    notes = []
    for task in report.tasks():
        checks = [c for c in report.checks if c.task == task]
        if all(c.exception == "NotImplementedError" for c in checks):
            notes.append(f"task{task}: not attempted")
            continue
        kinds = []
        for check in checks:
            text = check.message.strip().splitlines()[0] if check.message.strip() else ""
            if check.exception in _KNOWN:
                kinds.append(_KNOWN[check.exception])
            elif check.exception == "SubmissionRaised" and "sys.exit" in text:
                kinds.append("called sys.exit")
            elif check.exception == "DelegationRefused":
                used = text.split("your code used ", 1)[-1].split(",", 1)[0]
                kinds.append(f"delegation refused: called the engine's answer {used}")
            elif (
                check.exception in ("SubmissionError", "FileNotFoundError")
                and " is missing from " not in text  # the copy's note already says so
            ):
                kinds.append(text or "task file could not be loaded")
        notes += [f"task{task}: {kind}" for kind in dict.fromkeys(kinds)]
    return notes


def _reason(note: str) -> str:
    """The kind of problem a note describes, for the summary's counts."""
    return note.split(": ", 1)[-1] if note.startswith("task") else note.split(":", 1)[0]
