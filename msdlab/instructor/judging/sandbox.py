"""Running a submission in a separate, restricted process and talking to it as data.

The grader's checks use `RemoteImplementation` like any other implementation
(``implementation.task(n).some_function(...)``), but the submission's code runs
only in a child process (`sandbox_child`). Calls cross a pipe as plain data
(`wire`), so whatever the submission does to its own process (monkeypatching
numpy or pytest, printing fake results, exiting, looping, eating memory) cannot
decide a check: the verdict is computed here, from the numbers it sent back.

Isolation is by the operating system (``namespace``, the default): the child
runs under Debian's ``bubblewrap`` in its own user (without root), PID, mount,
IPC, UTS and network namespaces, seeing only a read-only copy of the
submission's task files, the Python environment read-only, its own ``/proc``
and a private, size-limited ``/tmp``; as root it runs as a reserved user id
without capabilities. Everything it starts dies with it. ``process`` is the
weaker level an instructor must ask for: a plain child process as the
grader's user. Both add resource limits (CPU time, memory, file size, and no
process or thread started once the engine has loaded), a processor-time budget
per function of a task and a per-call limit of the call's own time (`CallClock`)
after which the process is killed and restarted, and an audit hook whose only
job is friendly messages, not the boundary. Whatever the submission's process
does to itself is the submission's outcome; only evidence it cannot produce
(`INFRASTRUCTURE_FAILURES`) is the grader's.
"""

from __future__ import annotations

import builtins
import contextlib
import json
import os
import select
import shutil
import signal
import subprocess
import sys
import sysconfig
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ... import Integrator
from ...course.delegation import DelegationRefused
from ...course.report import WHERE
from ...engine.backends.contract import SpringKernel
from . import processes, wire

CHILD = Path(__file__).with_name("sandbox_child.py")
PACKAGE = Path(__file__).resolve().parents[2]
CHILD_IN_PACKAGE = CHILD.resolve().relative_to(PACKAGE).as_posix()
"""The child's path inside the msdlab package (``instructor/judging/sandbox_child.py``)."""
CALLBACK_NAMES = frozenset({"acceleration", "force", "masses", "free"})
STARTUP_SECONDS = 60.0  # the interpreter and numpy/scipy must load, even on a busy machine
ISOLATION_LEVELS = ("namespace", "process")
SCRATCH_BYTES = 64 * 2**20  # the private /tmp of one sandbox
INSIDE_LIBRARY = "/sandbox/lib"  # where the msdlab package is seen inside the sandbox
INSIDE_FOLDER = "/submission"  # where the submission's task files are seen
INSIDE_SCRATCH = "/tmp"
KILLED = -signal.SIGKILL
"""The exit status of bubblewrap itself killed by SIGKILL: outside the submission's
namespaces, only something outside the sandbox can send it that (a submission's process
that ends itself ends bubblewrap with 128 + the signal)."""
ENABLE_HINT = (
    "install bubblewrap (Debian/Ubuntu: apt-get install bubblewrap) and, when not root, "
    "allow unprivileged user namespaces (sysctl kernel.unprivileged_userns_clone=1 and "
    "kernel.apparmor_restrict_unprivileged_userns=0 where they exist); or grade with the "
    "weaker --isolation process"
)


def python_environment() -> list[Path]:
    """The folders the sandboxed interpreter needs, read-only: the interpreter's
    prefixes, the real interpreter and the installed libraries (never the course)."""
    paths = {"/usr", sys.prefix, sys.base_prefix, sys.exec_prefix}
    paths |= {sysconfig.get_paths()[key] for key in ("stdlib", "platstdlib")} | set(_sites())
    paths.add(os.path.dirname(os.path.realpath(sys.executable)))
    folders = sorted({Path(os.path.realpath(p)) for p in paths} | {Path(p) for p in paths})
    chosen: list[Path] = []
    for folder in folders:  # parents first; a folder inside a chosen one is already there
        if folder.is_dir() and not any(folder.is_relative_to(c) for c in chosen):
            chosen.append(folder)
    return chosen


def bubblewrap_command(
    folder: Path, command: Sequence[str], uid: int | None, scratch_bytes: int = SCRATCH_BYTES
) -> list[str]:
    """``command`` wrapped in bubblewrap: own namespaces, a private ``/tmp`` of
    ``scratch_bytes`` bytes, then the Python environment and msdlab read-only
    (mounted after ``/tmp``, so an environment living under ``/tmp`` stays
    visible), the submission ``folder`` read-only at ``INSIDE_FOLDER``. As root,
    ``uid`` is the user it runs as, with no capabilities."""
    wrap = ["bwrap", "--die-with-parent", "--new-session", "--unshare-ipc", "--unshare-pid"]
    wrap += ["--unshare-net", "--unshare-uts", "--unshare-cgroup-try"]
    if os.geteuid() != 0:  # as root the user namespace would map only root: setpriv drops it
        wrap.append("--unshare-user")
    wrap += ["--proc", "/proc", "--dev", "/dev"]
    wrap += ["--size", str(scratch_bytes), "--perms", "1777", "--tmpfs", INSIDE_SCRATCH]
    for link in ("bin", "lib", "lib64", "sbin"):
        target = Path("/") / link
        if target.is_symlink():
            wrap += ["--symlink", os.readlink(target), str(target)]
        elif target.is_dir():
            wrap += ["--ro-bind", str(target), str(target)]
    binds = [(path, path) for path in python_environment()]
    if Path("/etc/ld.so.cache").is_file():
        binds.append((Path("/etc/ld.so.cache"), Path("/etc/ld.so.cache")))
    binds += [(PACKAGE, Path(INSIDE_LIBRARY, "msdlab")), (Path(folder), Path(INSIDE_FOLDER))]
    parents = {parent for _, inside in binds for parent in inside.parents}
    for parent in sorted(parents - {Path("/"), Path(INSIDE_SCRATCH)}):  # bwrap's own are 0700
        wrap += ["--perms", "0755", "--dir", str(parent)]
    for source, inside in binds:
        wrap += ["--ro-bind", str(source), str(inside)]
    wrap += ["--chdir", INSIDE_SCRATCH]
    if os.geteuid() == 0:
        user = 65534 if uid is None else uid
        drop = [f"--reuid={user}", f"--regid={user}", "--clear-groups", "--no-new-privs"]
        drop += ["--inh-caps=-all", "--bounding-set=-all"]
        return [*wrap, "--", "/usr/bin/setpriv", *drop, "--", *command]
    return [*wrap, "--disable-userns", "--", *command]


def isolation_problem(level: str = "namespace") -> str | None:
    """Why sandboxes of isolation ``level`` cannot start here (None if they can),
    with how to enable them; tried once with a tiny sandbox."""
    if level not in ISOLATION_LEVELS:
        return f"unknown isolation {level!r}; choose one of {', '.join(ISOLATION_LEVELS)}"
    if level == "process":
        return None
    if shutil.which("bwrap") is None:
        return (
            f"the grading sandbox needs bubblewrap (bwrap), which is not installed: {ENABLE_HINT}"
        )
    if os.geteuid() == 0 and not Path("/usr/bin/setpriv").is_file():
        return "the grading sandbox needs /usr/bin/setpriv (util-linux) when run as root"
    with tempfile.TemporaryDirectory(prefix="msdlab-probe-") as folder:
        path = [INSIDE_LIBRARY, *_sites()]
        command = [
            sys.executable,
            "-I",
            "-S",
            "-c",
            f"import sys; sys.path[:0] = {path!r}; import msdlab",
        ]
        try:
            result = subprocess.run(
                bubblewrap_command(Path(folder), command, None),
                capture_output=True,
                timeout=STARTUP_SECONDS,
                env={"PATH": "/usr/bin:/bin"},
                check=False,
            )
        except (OSError, subprocess.TimeoutExpired) as error:
            return f"the grading sandbox could not start ({error}): {ENABLE_HINT}"
    if result.returncode != 0:
        reason = result.stderr.decode(errors="replace").strip().splitlines()[-1:] or ["?"]
        return f"the grading sandbox could not start ({reason[0]}): {ENABLE_HINT}"
    return None


def _sites() -> list[str]:
    """The folders of the installed libraries: this environment's and those numpy and
    scipy were imported from."""
    import scipy

    folders = {sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]}
    folders |= {str(Path(module.__file__).parents[1]) for module in (np, scipy)}
    return sorted(folders)


class SandboxError(Exception):
    """The submission's process could not answer (timeout, crash, broken channel)."""


class SubmissionTimeout(SandboxError):
    """A call into the submission took longer than the time limit."""


class SandboxLost(SandboxError):
    """The sandbox was ended from outside, on evidence its own code cannot produce (bubblewrap,
    outside the submission's namespaces, killed): the machine's failure, not the
    submission's."""


class SandboxUnavailable(SandboxError):
    """The sandbox could not start (before any of the submission's code ran): the grader's
    failure."""


class MachineBusy(SubmissionTimeout):
    """A call ran long because its sandbox was ready to run and was not given a processor
    (its own scheduling figures say so): the machine's failure, not the submission's."""


class SubmissionWaited(SubmissionTimeout):
    """A call took longer than the time limit while the submission slept or was blocked."""


INFRASTRUCTURE_FAILURES = frozenset(
    {SandboxLost.__name__, SandboxUnavailable.__name__, MachineBusy.__name__}
)
"""The exceptions a check may end with that are no fault of the submission."""


class SubmissionCrashed(SandboxError):
    """The submission's process died or broke the channel."""


class SubmissionRaised(Exception):
    """The submission raised an exception that is not a Python built-in one."""


STARVED_FACTOR = 10.0
"""A call that has run this many times its time limit, without having had the limit's time
of its own, is the machine's failure (`MachineBusy`)."""


class CallClock:
    """The time of one call into the submission, as it is charged.

    Its processor time is charged against the function's budget (the time the submission's
    processes use: a busy machine does not eat a student's time, and an endless loop costs
    the budget however loaded the machine is). Its time limit is measured in its own time:
    the wall-clock time of the call less the time its sandbox was ready to run and waited
    for a processor (the kernel's scheduling figures, `processes.scheduled`), and less the
    time it waited for the judge to serve its callbacks (`served`: the judge's wait for a
    processor once woken by the callback, and its time serving it). A sleeping or blocked
    sandbox spends its own time; a starved one does not."""

    POLL_SECONDS = 1.0  # how often the charge is looked at while waiting

    def __init__(
        self,
        processor: Callable[[], float],
        budget: float | None,
        waits: Callable[[], float] = lambda: 0.0,
    ) -> None:
        self.processor, self.budget, self.waits = processor, budget, waits
        self._start = self._seen = processor()
        self._started, self._waited = time.monotonic(), waits()
        self.served = 0.0  # seconds the sandbox waited for the judge to serve its callbacks
        self.woken = 0.0  # seconds the judge waited for a processor since it last served

    def charged(self) -> float:
        """Processor seconds used so far (what ended processes used stays charged)."""
        self._seen = max(self._seen, self.processor())
        return self._seen - self._start

    def over_budget(self) -> bool:
        """True once the call has been charged its budget."""
        return self.budget is not None and self.charged() >= self.budget

    def elapsed(self) -> float:
        """Wall-clock seconds since the call started."""
        return time.monotonic() - self._started

    def own(self) -> float:
        """The call's own seconds so far: wall-clock time less the waits of `waits` and the
        time it waited for its callbacks."""
        return self.elapsed() - (self.waits() - self._waited) - self.served

    def served_since(self, started: float) -> None:
        """The judge has served a callback since ``started`` (`time.monotonic`): the sandbox
        waited for it that long, and for the judge to be given a processor before."""
        self.served += self.woken + time.monotonic() - started
        self.woken = 0.0

    def timed_out(self, limit: float) -> SubmissionTimeout:
        """The error of a call that ran ``limit`` seconds of its own: an endless loop's where
        it computed most of them, a sleeper's where it slept or blocked."""
        if self.charged() >= 0.5 * self.own():
            return SubmissionTimeout(
                f"the submission did not answer within {limit:g} s, computing all along "
                "(an endless loop, or far too much work?)"
            )
        return SubmissionWaited(
            f"the submission did not answer within {limit:g} s: it was waiting (sleeping or "
            "blocked), not computing, most of that time"
        )

    def starved(self, limit: float) -> MachineBusy:
        """The error of a call whose sandbox was kept from a processor."""
        return MachineBusy(
            f"no answer within {self.elapsed():.0f} s, of which the call had only "
            f"{max(self.own(), 0.0):.0f} s of its own (limit {limit:g} s): its sandbox was "
            "ready to run and waited for a processor the rest of the time"
        )


class SandboxProcess:
    """One restricted child process serving one submission folder; restarted after a failure."""

    def __init__(
        self,
        folder: Path,
        *,
        timeout: float = 60.0,
        task_timeout: float | None = None,
        memory_bytes: int = 2 * 2**30,
        uid: int | None = None,
        isolation: str = "namespace",
    ) -> None:
        if isolation not in ISOLATION_LEVELS:
            raise ValueError(f"isolation must be one of {ISOLATION_LEVELS}, not {isolation!r}")
        self.folder = Path(folder).resolve()
        self.timeout = timeout
        self.task_timeout = task_timeout  # processor seconds of a function in one task's checks
        self.task: int | None = None  # the task of the check running now
        self.spent: dict[tuple[int, str], float] = {}  # processor seconds by task and function
        self.used = 0.0  # processor seconds of the processes closed so far
        self.memory_bytes = memory_bytes
        self.uid = uid if uid is not None else 65534
        self.strong = isolation == "namespace"
        self.generation = 0
        self.process: subprocess.Popen | None = None
        self.scratch = Path(tempfile.mkdtemp(prefix="msdlab-sandbox-"))  # the grader's files
        (self.scratch / "lib").mkdir()
        (self.scratch / "lib" / "msdlab").symlink_to(PACKAGE, target_is_directory=True)
        self.exports: dict[int, Any] = {}
        self.members: dict[tuple[int, str], wire.Ref] = {}
        self.broken: dict[str, SandboxError] = {}  # name -> its failure, until `forgive`
        self.refused_task: int | None = None  # whose engine answers the submission may not use
        self._deadline, self._limit = 0.0, timeout  # of the answer being waited for
        self._clock = CallClock(lambda: 0.0, None)  # the time the current call is charged
        self._clock_of_child: processes.ProcessorClock | None = None  # found at first need
        self._judge_schedule = processes.held_schedule()  # this thread's: it serves the calls
        self._key: tuple[int, str] | None = None  # the budget the current call is charged to
        self._answered = False  # whether the child started now has answered

    @property
    def isolation(self) -> str:
        """A short description of the isolation in force."""
        if self.strong:
            return "own namespaces (bubblewrap), resource limits, audit hook"
        return "separate process as the grader's user, resource limits, audit hook"

    # ------------------------------------------------------------ lifecycle
    def start(self) -> None:
        """Start the child and wait until it answers (never falling back to weaker isolation)."""
        self._launch()
        try:
            self.request({"op": "ping"}, timeout=STARTUP_SECONDS)
            self._answered = True
        except (SandboxLost, MachineBusy):
            raise
        except SandboxError as error:  # no code of the submission has run yet
            reason = f"cannot start the grading sandbox ({error}): {self.log_tail()}"
            raise SandboxUnavailable(reason) from None

    def log_tail(self, limit: int = 2000) -> str:
        """The end of what the submission printed (its stdout and stderr)."""
        try:
            return (self.scratch / "output.log").read_text(errors="replace")[-limit:]
        except OSError:
            return ""

    def _launch(self) -> None:
        self.close()
        self._answered = False  # the processes' clock is found once the child answers
        to_child, self._send_fd = os.pipe()
        self._recv_fd, from_child = os.pipe()
        self._reader = wire.Reader(self._recv_fd, self._wait_for_answer)  # nothing left over
        sites = _sites()
        if self.strong:
            folder, scratch, library = INSIDE_FOLDER, INSIDE_SCRATCH, INSIDE_LIBRARY
        else:  # a fresh scratch each start: nothing planted there runs on the next one
            shutil.rmtree(self.scratch / "scratch", ignore_errors=True)
            (self.scratch / "scratch").mkdir()
            folder, scratch, library = (
                str(self.folder),
                str(self.scratch / "scratch"),
                str(self.scratch / "lib"),
            )
        package = f"{library}/msdlab"  # the guard resolves the link to where it really is
        child = f"{package}/{CHILD_IN_PACKAGE}"
        config = {
            "folder": folder,
            "scratch": scratch,
            "sys_path": [library, *sites],
            "read_roots": [folder, library, package, sys.prefix, sys.base_prefix, *sites],
            "memory_bytes": self.memory_bytes,
            "cpu_seconds": int(max(600.0, 100 * self.timeout)),  # a whole set of checks
            "in_fd": to_child,
            "out_fd": from_child,
        }
        command = [sys.executable, "-I", "-S", "-B", child, json.dumps(config)]
        if self.strong:
            command = bubblewrap_command(self.folder, command, self.uid)
        environment = {
            "PATH": "/usr/bin:/bin",
            "MSDLAB_KERNEL": "numpy",
            "OPENBLAS_NUM_THREADS": "1",
            "OMP_NUM_THREADS": "1",
            "MKL_NUM_THREADS": "1",
        }
        with (self.scratch / "output.log").open("ab") as log:  # the grader's side only
            self.process = subprocess.Popen(
                command,
                pass_fds=(to_child, from_child),
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=log,
                env=environment,
                start_new_session=True,
            )
        os.close(to_child)
        os.close(from_child)
        self.exports.clear()
        self.members.clear()

    def close(self) -> None:
        """Kill the child (and anything it started) and close the pipes; its objects are gone."""
        if self.process is not None:
            self.generation += 1
            self.used += self._processor_time()  # read before it is ended
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait()
            if self._clock_of_child is not None:
                self._clock_of_child.close()
                self._clock_of_child = None
            for fd in (self._send_fd, self._recv_fd):
                with contextlib.suppress(OSError):
                    os.close(fd)
            self.process = None

    def cleanup(self) -> None:
        """Close the child and delete its scratch folder."""
        self.close()
        for handle in self._judge_schedule:
            os.close(handle)
        self._judge_schedule = []
        shutil.rmtree(self.scratch, ignore_errors=True)

    # ------------------------------------------------------------ requests
    def forgive(self) -> None:
        """Let functions that timed out or crashed run again (called before each check)."""
        self.broken.clear()

    def begin_check(self, task: int | None) -> None:
        """A check of ``task`` starts: its calls draw on that task's time (`task_timeout`)."""
        self.forgive()
        self.task = task

    def _budget_key(self, name: str) -> tuple[int, str] | None:
        """What a call of ``name`` is charged to: its function (``task2.spring_force()`` and
        ``task5.Verlet().step()`` are ``task2.spring_force`` and ``task5.Verlet.step``) in
        the current task's checks; None without a task budget."""
        if self.task_timeout is None or self.task is None:
            return None
        return self.task, name.replace("()", "")

    def _time_left(self, key: tuple[int, str] | None) -> float | None:
        """Processor seconds the calls charged to ``key`` may still take (None: no budget)."""
        if key is None:
            return None
        return self.task_timeout - self.spent.get(key, 0.0)

    def request(
        self,
        message: dict,
        generation: int | None = None,
        name: str = "",
        timeout: float | None = None,
        arguments: dict[str, Any] | None = None,
    ) -> Any:
        """Send ``message`` and return the child's answer, serving its callbacks meanwhile.

        ``arguments`` (a call's array arguments by position or name) receive the
        changes the call made to its copies of them (see `write_back`).

        The answer must come within ``timeout`` (default: the call time limit). A
        call of ``name`` that timed out or killed the process is not run again until
        `forgive`: it fails at once the same way, so one endless or crashing function
        costs one time limit or one restart per check, however often the check calls it.
        Its processor time is charged to its function's budget in the current task
        (`_budget_key`), so an endless loop in one function costs that function's checks,
        not the rest of its task's.
        """
        if name in self.broken:
            error = self.broken[name]
            raise type(error)(f"{name}: {error} (not run again in this check)")
        if generation is not None and generation != self.generation:
            raise SubmissionCrashed(
                "this object was lost when the submission's process was restarted after a failure"
            )
        key = self._budget_key(name or "the import of its task files") if timeout is None else None
        left = self._time_left(key)
        if left is not None and left <= 0:
            raise SubmissionTimeout(f"not run: {self._used_up(key)}")
        if self.process is None:
            self.start()
        limit = self.timeout if timeout is None else timeout
        self._clock = CallClock(self._processor_time, left, self._waits)
        self._key = key
        try:
            return self._exchange(message, name, arguments, limit, time.monotonic() + limit)
        finally:
            if key is not None:
                self.spent[key] = self.spent.get(key, 0.0) + self._clock.charged()

    def _child_clock(self) -> processes.ProcessorClock | None:
        """The clock of the child's processes, found once they have answered (all of them
        run by then: bubblewrap's and the child's)."""
        if self.process is None or not self._answered:
            return None
        if self._clock_of_child is None:
            pids = processes.descendants(self.process.pid)
            self._clock_of_child = processes.ProcessorClock(pids)
        return self._clock_of_child

    def _processor_time(self) -> float:
        """Processor seconds the child's processes have used."""
        clock = self._child_clock()
        return 0.0 if clock is None else clock.seconds()

    def _waits(self) -> float:
        """Seconds the sandbox's processes have waited, ready to run, for a processor; 0
        where the kernel keeps no scheduling figures."""
        clock = self._child_clock()
        figures = None if clock is None else clock.scheduled()
        return figures[1] if figures else 0.0

    def _used_up(self, key: tuple[int, str] | None) -> str:
        task, function = key if key is not None else (self.task, "")
        return (
            f"the submission's code used up the {self.task_timeout:g} s of processor time "
            f"{function} may take in task {task}'s checks (an endless loop, or far too much "
            "work?)"
        )

    def _exchange(
        self, message: dict, name: str, arguments: dict[str, Any] | None, limit: float,
        deadline: float,
    ) -> Any:  # fmt: skip
        """Send ``message``, serve the child's callbacks, and return its answer (see
        `request`)."""
        try:
            wire.write_all(self._send_fd, wire.encode(message, self._export))
            while True:
                reply = self._receive(deadline, limit)
                if isinstance(reply, dict) and "op" in reply:
                    started = time.monotonic()
                    wire.write_all(self._send_fd, self._serve(reply))
                    self._clock.served_since(started)
                    continue
                break
        except SubmissionTimeout as error:
            self.close()
            self._remember(name, error)
            raise
        except (EOFError, BrokenPipeError, wire.WireError, ValueError, KeyError) as error:
            reason = self._death_reason() or f"the channel broke ({error})"
            lost = self.strong and self.process is not None and self.process.returncode == KILLED
            self.close()
            if lost:
                raise SandboxLost(f"the sandbox was killed from outside ({reason})") from None
            crash = SubmissionCrashed(f"the submission's process {reason}")
            self._remember(name, crash)
            raise crash from None
        if not isinstance(reply, dict) or not ("ok" in reply or "error" in reply):
            self.close()
            raise SubmissionCrashed("the submission's process sent a malformed answer")
        if "error" in reply:
            _raise(reply["error"])
        if arguments is not None and "args" in reply:
            write_back(arguments, reply["args"], name)
        return reply["ok"]

    def _remember(self, name: str, error: SandboxError) -> None:
        if name:
            self.broken[name] = error

    def _receive(self, deadline: float, limit: float) -> Any:
        self._deadline, self._limit = deadline, limit
        return wire.decode(self._reader)

    def _wait_for_answer(self) -> None:
        """Wait until the child has written something, or raise `SubmissionTimeout`."""
        while True:
            remaining = self._deadline - time.monotonic()
            wait = max(min(remaining, CallClock.POLL_SECONDS), 0)
            before = processes.scheduled(self._judge_schedule)
            if select.select([self._recv_fd], [], [], wait)[0]:
                after = processes.scheduled(self._judge_schedule)
                if before and after:  # what the judge waited for a processor once woken
                    self._clock.woken += after[1] - before[1]
                return
            if self._clock.over_budget():
                raise SubmissionTimeout(self._used_up(self._key))
            if time.monotonic() < self._deadline:
                continue
            own = self._clock.own()
            if own >= self._limit:
                raise self._clock.timed_out(self._limit)
            if self._clock.elapsed() >= STARVED_FACTOR * self._limit:
                raise self._clock.starved(self._limit)
            self._deadline = time.monotonic() + self._limit - own  # the rest of its own time

    def _death_reason(self) -> str:
        if self.process is None:
            return ""
        try:
            code = self.process.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            return ""
        number = -code if code < 0 else code - 128 if self.strong and code > 128 else 0
        if number:  # bubblewrap exits with 128 + the signal that ended its child
            name = signal.Signals(number).name if number in set(signal.Signals) else number
            return f"was ended by the signal {name}"
        return f"exited with status {code}"

    def _export(self, value: Any) -> wire.Ref:
        """A grader object handed to the submission (only its whitelisted members)."""
        if isinstance(value, RemoteObject):
            return value._ref
        self.exports[id(value)] = value
        return wire.Ref(id(value), "grader")

    def _serve(self, request: dict) -> bytes:
        """Answer a callback, encoded: a whitelisted attribute or a call of an exported
        callable (an answer that is not plain data is an error for the submission)."""
        try:
            target = self.exports[request["ref"].id]
            if request["op"] == "getattr":
                name = request["name"]
                if name not in CALLBACK_NAMES:
                    raise AttributeError(f"the submission may only use {sorted(CALLBACK_NAMES)}")
                key = (id(target), name)
                if key not in self.members:
                    value = getattr(target, name)
                    if not callable(value):
                        return wire.encode({"ok": value})
                    self.members[key] = self._export(value)
                return wire.encode({"ok": self.members[key]})
            if request["op"] == "call" and callable(target):
                args = [np.asarray(a, dtype=float) for a in request["args"]]
                return wire.encode({"ok": target(*args)})
            raise ValueError("unknown callback")
        except Exception as error:
            return wire.encode({"error": f"{type(error).__name__}: {error}"})


def write_back(arguments: dict[str, np.ndarray], changed: Any, name: str) -> None:
    """Apply to the caller's arrays what the submission's call did to its copies of them.

    In one process the checks see a function change its arguments in place; through
    the sandbox they see it the same way. Only changes of values are applied (NaN and
    inf included, as in one process); a call that changed an argument's shape or
    dtype fails the check with `ArgumentChanged` instead of reaching the judge.
    """
    if not isinstance(changed, dict):
        raise SubmissionCrashed("the submission's process sent a malformed answer")
    for key, new in changed.items():
        target = arguments.get(key)
        if target is None:
            continue
        where = f"argument {int(key) + 1}" if key.isdigit() else f"argument '{key}'"
        if not isinstance(new, np.ndarray):
            shape = new.get("shape") if isinstance(new, dict) else "?"
            dtype = new.get("dtype") if isinstance(new, dict) else "?"
            raise ArgumentChanged(
                f"{name} changed its {where} in place from an array of shape "
                f"{target.shape} ({target.dtype}) to shape {tuple(shape)} ({dtype}): "
                "functions must not resize or retype the arrays they are given"
            )
        if new.shape != target.shape or new.dtype != target.dtype:
            raise ArgumentChanged(
                f"{name} changed its {where} in place to shape {new.shape} ({new.dtype}), "
                f"given {target.shape} ({target.dtype})"
            )
        if not target.flags.writeable:
            raise ValueError(f"{name}: assignment destination is read-only ({where})")
        np.copyto(target, new)


class ArgumentChanged(AssertionError):
    """A submission's function changed the shape or dtype of an array it was given."""


def _raise(error: dict) -> None:
    """Raise the submission's error here: built-in types keep their type, others are wrapped.
    Its message ends with the line of the submission that raised it, as a check run in one
    process says it (`msdlab.course.failure.raised_in`; a to-do without its code)."""
    name, message = str(error.get("type")), str(error.get("message"))
    text = message + _raised_in(error, code=name != "NotImplementedError")
    if name == "DelegationRefused":  # the same failure as in one process
        raise DelegationRefused(message)
    kind = getattr(builtins, name, None)
    if (
        isinstance(kind, type)
        and issubclass(kind, Exception)
        and not issubclass(kind, (SystemExit, KeyboardInterrupt, GeneratorExit))
    ):
        raise kind(text)
    raise SubmissionRaised(f"{name}: {text}")


def _raised_in(error: dict, code: bool) -> str:
    """'\nin your code: task2.py, line 51, in spring_acceleration' and (with ``code``) the
    line's code, from the child's description of an error; '' without one."""
    if not error.get("file"):
        return ""
    where = f"\n{WHERE}{error['file']}, line {error.get('line')}, in {error.get('function')}"
    return where + (f"\n    {error['code']}" if code and error.get("code") else "")


class RemoteObject:
    """An object of the submission: attribute access and calls go to its process."""

    def __init__(self, sandbox: SandboxProcess, ref: wire.Ref, name: str) -> None:
        self._sandbox, self._ref, self._name = sandbox, ref, name
        self._generation = sandbox.generation

    def _request(self, message: dict, name: str, arguments: dict | None = None) -> Any:
        value = self._sandbox.request(message, self._generation, self._name, arguments=arguments)
        return _wrap(self._sandbox, value, name)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        message = {"op": "getattr", "ref": self._ref, "name": name}
        return self._request(message, f"{self._name}.{name}")

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        message = {"op": "call", "ref": self._ref, "args": args, "kwargs": kwargs}
        return self._call(message, self._name, args, kwargs)

    def _call_method(self, name: str, *args: Any, hint: dict | None = None) -> Any:
        """``self.name(*args)`` in one round trip: the submission looks the method up and calls
        it, as ``getattr`` and a call of what it returns would. ``hint``: a callback's answer
        sent along (see `_acceleration_hint`)."""
        message = {"op": "call", "ref": self._ref, "name": name, "args": args, "kwargs": {}}
        if hint is not None:
            message["hint"] = hint
        return self._call(message, f"{self._name}.{name}", args, {})

    def _call(self, message: dict, name: str, args: tuple, kwargs: dict) -> Any:
        message["refuse"] = self._sandbox.refused_task  # see msdlab.course.delegation
        arguments = {**{str(i): a for i, a in enumerate(args)}, **kwargs}
        arrays = {k: a for k, a in arguments.items() if isinstance(a, np.ndarray)}
        value = self._sandbox.request(message, self._generation, name, arguments=arrays)
        return _wrap(self._sandbox, value, f"{name}()")

    def __repr__(self) -> str:
        return f"<submission {self._ref.kind}>"


def _acceleration_hint(dynamics: Any, x: np.ndarray, v: np.ndarray) -> dict | None:
    """The engine's ``dynamics.acceleration(x, v)`` at the state a step starts from, computed
    here and sent with the step: the submission's process answers its own call of it at
    exactly that state (the same numbers, as floats) without calling back, which halves the
    round trips of a step. A call at any other state calls back as before. None where the
    engine cannot compute it (the step's own call then fails the same way)."""
    if isinstance(dynamics, RemoteObject) or not hasattr(dynamics, "acceleration"):
        return None
    try:
        answer = np.asarray(dynamics.acceleration(x, v), dtype=float)
        args = [np.asarray(x, dtype=float), np.asarray(v, dtype=float)]
    except Exception:
        return None
    return {"ref": dynamics, "name": "acceleration", "args": args, "ok": answer}


class RemoteIntegrator(RemoteObject, Integrator):
    """A submission's `Integrator`: the engine steps it, each step runs in the sandbox.

    Each method call is one round trip; `step` carries the engine's acceleration at the
    state it starts from (`_acceleration_hint`), so a step that asks for it there calls
    nothing back. `velocity_at_positions`, `dissipated_energy`
    and `velocity_factor` that the submission's class takes unchanged from
    `Integrator` run here, as the engine's own code: the engine calls them at
    every step, and an answer of the submission's process that they are
    unchanged when they are not gains it nothing it could not have by returning
    those same numbers.
    """

    ENGINE_DEFAULTS = ("velocity_at_positions", "dissipated_energy", "velocity_factor")

    def __init__(self, sandbox: SandboxProcess, ref: wire.Ref, name: str) -> None:
        super().__init__(sandbox, ref, name)
        self._inherited: frozenset[str] | None = None

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Any) -> Any:
        hint = _acceleration_hint(dynamics, x, v)
        return self._call_method("step", x, v, dt, dynamics, hint=hint)

    def dissipated_energy(
        self,
        v: np.ndarray,
        masses: np.ndarray,
        v_new: np.ndarray | None = None,
        *,
        kernel: SpringKernel | None = None,
    ) -> float:
        if self._engine_default("dissipated_energy"):
            return Integrator.dissipated_energy(self, v, masses, v_new, kernel=kernel)
        return self._call_method("dissipated_energy", v, masses, v_new)

    @property
    def velocity_factor(self) -> float:
        if self._engine_default("velocity_factor"):
            return Integrator.velocity_factor.fget(self)
        return float(self.__getattr__("velocity_factor"))

    def velocity_at_positions(self, v: np.ndarray, a: np.ndarray, dt: float) -> np.ndarray:
        if self._engine_default("velocity_at_positions"):
            return Integrator.velocity_at_positions(self, v, a, dt)
        return self._call_method("velocity_at_positions", v, a, dt)

    def _engine_default(self, name: str) -> bool:
        """True if the submission's integrator takes ``name`` unchanged from `Integrator`
        (asked once per integrator)."""
        if self._inherited is None or self._generation != self._sandbox.generation:
            message = {"op": "inherited", "ref": self._ref, "names": list(self.ENGINE_DEFAULTS)}
            answer = self._sandbox.request(message, self._generation, self._name)
            names = answer if isinstance(answer, list) else []
            self._inherited = frozenset(n for n in names if n in self.ENGINE_DEFAULTS)
        return name in self._inherited

    def __repr__(self) -> str:
        try:
            return str(self._call_method("__repr__"))
        except Exception:
            return "<submission integrator>"

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__") and name != "__repr__":
            raise AttributeError(name)
        message = {"op": "getattr", "ref": self._ref, "name": name}
        return self._request(message, f"{self._name}.{name}")


def _wrap(sandbox: SandboxProcess, value: Any, name: str) -> Any:
    """Answers as they are, with references to the submission's objects as proxies."""
    if isinstance(value, wire.Ref):
        kind = RemoteIntegrator if value.kind == "integrator" else RemoteObject
        return kind(sandbox, value, name)
    if isinstance(value, list):
        return [_wrap(sandbox, v, name) for v in value]
    if isinstance(value, tuple):
        return tuple(_wrap(sandbox, v, name) for v in value)
    if isinstance(value, dict):
        return {k: _wrap(sandbox, v, name) for k, v in value.items()}
    return value


class RemoteTask:
    """A task module of the submission; survives restarts of the process."""

    def __init__(self, sandbox: SandboxProcess, number: int) -> None:
        self._sandbox, self._number = sandbox, number
        self._module: RemoteObject | None = None

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        if self._module is None or self._module._generation != self._sandbox.generation:
            answer = self._sandbox.request({"op": "task", "n": self._number})
            self._module = _wrap(self._sandbox, answer, f"task{self._number}")
        return getattr(self._module, name)

    def __repr__(self) -> str:
        return f"<sandboxed task{self._number}.py of {self._sandbox.folder}>"


class RemoteImplementation:
    """A submission folder whose task modules run in a `SandboxProcess` (see module docstring)."""

    def __init__(self, folder: Path, label: str | None = None, **options: Any) -> None:
        self.sandbox = SandboxProcess(folder, **options)
        self.label = label or str(self.sandbox.folder)
        self._tasks: dict[int, RemoteTask] = {}

    def task(self, number: int) -> RemoteTask:
        return self._tasks.setdefault(number, RemoteTask(self.sandbox, number))

    def forgive(self) -> None:
        """A new check starts: functions that timed out may run again."""
        self.sandbox.forgive()

    def begin_check(self, task: int | None) -> None:
        """A check of ``task`` starts (see `SandboxProcess.begin_check`)."""
        self.sandbox.begin_check(task)

    def refuse_delegation(self, task: int | None) -> None:
        """From now on the engine's answer to ``task`` refuses the submission's calls (None:
        nothing is refused); see `msdlab.course.delegation`."""
        self.sandbox.refused_task = task

    def close(self) -> None:
        self.sandbox.cleanup()
