"""pytest plugin of the course checks (registered as the ``pytest11`` entry point ``msdlab``).

- ``--impl=solutions|assignments|PATH`` chooses the implementation under test
  (fallback: the ``MSDLAB_IMPL`` environment variable; default: ``assignments``,
  the student's files, even where the course root holds ``solutions/``). PATH is a
  folder laid out like ``assignments/``. The header names the files under test.
- Fixtures ``implementation`` (see `msdlab.course.loader`) and ``task1`` ...
  ``task5`` (the task modules). Override ``implementation`` in a conftest to
  load submissions another way.
- Markers ``task1`` ... ``task5``, ``points(n)`` and ``hidden``. A graded check
  has exactly one task marker and its points; ``hidden`` checks are instructor-only.
- ``--call-timeout=S``: each call into the task modules, and each task file's import, may
  take S seconds (`msdlab.course.call_limit`; default: no limit). A function that did not
  return is not called again in the later checks of its task (each says so, once).
- ``--task-timeout=S``: each function of the task files may take S seconds of processor
  time in its task's checks, as when graded (`msdlab.course.task_budget`; default: no
  limit).
- ``--msdlab-progress=FD``: write a line ``TASK NAME`` to the file descriptor FD as each
  graded check starts (``msdlab check`` shows it while the checks run).
- ``--msdlab-points=PATH`` writes the points of every collected check, public and
  hidden, per task (`msdlab.course.manifest`).
- ``--msdlab-report=PATH`` writes the JSON `CheckReport` of the graded checks;
  a points summary ends the terminal output.
- `hypothesis_profiles`, called by the checks' conftest: profiles ``ci`` (no
  deadline, derandomised, no example database: reproducible grading; loaded
  unless ``--hypothesis-profile`` chooses another) and ``dev``. Hypothesis is
  imported only where checks use it (importing it takes about a second).
"""

from __future__ import annotations

import contextlib
import inspect
import os
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, NoReturn

import pytest

from . import TASKS, call_limit, delegation, failure, loader, manifest, own_numbers
from .report import CheckReport, CheckResult
from .task_budget import TaskBudget, TaskStopped, stuck_at

ENV_IMPL = loader.ENV_IMPL
_REPORT = pytest.StashKey[CheckReport]()
_STARTED = pytest.StashKey[float]()
_GRADED = pytest.StashKey[tuple[int, int, bool]]()
_BUDGET = pytest.StashKey[TaskBudget]()
_TIMED_OUT = pytest.StashKey[dict[str, str]]()
"""A timed-out call's message (without its check) -> the check it first timed out in."""
_LAST_TASK = pytest.StashKey[int]()


class Hooks:
    """Hooks other plugins may implement (the instructor's sandbox plugin does)."""

    @pytest.hookspec(firstresult=True)
    def pytest_msdlab_implementation(self, config: pytest.Config, spec: str, root: Path) -> Any:
        """Provide the implementation under test for ``spec`` in place of loading it here
        (it needs ``label`` and ``task(n)`` like `loader.Implementation`, and may have
        ``close()``); return None to let the course load it in this process."""


def pytest_addhooks(pluginmanager: pytest.PytestPluginManager) -> None:
    pluginmanager.add_hookspecs(Hooks)


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("msdlab", "msdlab course checks")
    group.addoption(
        "--impl",
        default=None,
        metavar="IMPL",
        help="implementation under test: 'solutions', 'assignments' or a folder laid out "
        f"like assignments/ (default: ${ENV_IMPL}, else {loader.DEFAULT})",
    )
    group.addoption(
        "--allow-delegation",
        default="",
        metavar="TASKS",
        help="comma-separated tasks whose checks let the implementation call the engine's "
        "answer to them (by default it is refused, see msdlab.course.delegation)",
    )
    group.addoption(
        "--call-timeout",
        type=float,
        default=0.0,
        metavar="S",
        help="seconds one call into the implementation, or one task file's import, may take "
        "(default 0: no limit)",
    )
    group.addoption(
        "--task-timeout",
        type=float,
        default=0.0,
        metavar="S",
        help="processor seconds each function of the implementation may take in its task's "
        "checks, all its calls together, as when graded (default 0: no limit)",
    )
    group.addoption(
        "--msdlab-progress",
        type=int,
        default=None,
        metavar="FD",
        help="write a line to the file descriptor FD as each graded check starts",
    )
    group.addoption(
        "--student",
        default=None,
        metavar="ID",
        help="grade against this student's own numbers (msdlab.course.own_numbers; default: "
        "the id in the implementation's student.json, else the template's numbers)",
    )
    group.addoption(
        "--msdlab-points",
        default=None,
        metavar="PATH",
        help="write the points of every graded check collected, public and hidden, per task, "
        "as JSON to PATH (before -m deselects any)",
    )
    group.addoption(
        "--msdlab-report",
        default=None,
        metavar="PATH",
        help="write the results of the graded checks as JSON to PATH",
    )


def pytest_configure(config: pytest.Config) -> None:
    for number in TASKS:
        config.addinivalue_line("markers", f"task{number}: a graded check of task {number}")
    config.addinivalue_line("markers", "points(n): the points a graded check is worth")
    config.addinivalue_line("markers", "hidden: instructor-only check, not in the student release")
    config.stash[_REPORT] = CheckReport(implementation=implementation_spec(config))
    config.stash[_STARTED] = time.perf_counter()
    config.stash[_TIMED_OUT] = {}
    seconds = config.getoption("task_timeout") or 0.0
    if seconds > 0:
        folder = loader.resolve(implementation_spec(config), loader.course_root(config.rootpath))
        config.stash[_BUDGET] = TaskBudget(seconds, folder)


def implementation_spec(config: pytest.Config) -> str:
    """The ``--impl`` value in force: the option, else $MSDLAB_IMPL, else the default."""
    return config.getoption("impl") or os.environ.get(ENV_IMPL) or loader.DEFAULT


def pytest_report_header(config: pytest.Config) -> str:
    """'msdlab: checking ...' at the top of pytest's output: whose task files are checked."""
    return f"msdlab: checking the task files of {loader.describe(implementation_spec(config))}"


@pytest.fixture(scope="session")
def implementation(pytestconfig: pytest.Config) -> Iterator[loader.Implementation]:
    """The implementation under test (see ``--impl``; a plugin implementing
    `Hooks.pytest_msdlab_implementation` may provide it instead)."""
    spec = implementation_spec(pytestconfig)
    root = loader.course_root(pytestconfig.rootpath)
    provided = pytestconfig.hook.pytest_msdlab_implementation(
        config=pytestconfig, spec=spec, root=root
    )
    if provided is None:
        yield loader.load(spec, root, pytestconfig.getoption("call_timeout"))
        return
    try:
        yield provided
    finally:
        close = getattr(provided, "close", None)
        if close is not None:
            close()


@pytest.fixture(scope="session", name="own_numbers")
def own_numbers_fixture(
    pytestconfig: pytest.Config, implementation: loader.Implementation
) -> own_numbers.Numbers:
    """The numbers of the student under test (`own_numbers`)."""
    student = pytestconfig.getoption("student")
    folder = getattr(implementation, "folder", None)
    if student is None and folder is not None:
        student = own_numbers.student_of(folder)
    return own_numbers.numbers(student)


def _task_fixture(number: int):
    @pytest.fixture(scope="session", name=f"task{number}")
    def task(implementation: loader.Implementation, pytestconfig: pytest.Config):
        pytestconfig.stash[_REPORT].implementation = implementation.label
        seconds = pytestconfig.getoption("call_timeout") or 0.0
        if seconds <= 0:
            return implementation.task(number)
        folder = getattr(implementation, "folder", None)
        try:
            with call_limit.time_limit(seconds, lambda: _import_stopped(number, seconds, folder)):
                return implementation.task(number)
        except loader.SubmissionError as error:  # the stop says what and where by itself
            if isinstance(error.__cause__, TaskStopped):
                raise error.__cause__ from None
            raise

    task.__doc__ = f"The module of task {number} of the implementation under test."
    return task


task1 = _task_fixture(1)
task2 = _task_fixture(2)
task3 = _task_fixture(3)
task4 = _task_fixture(4)
task5 = _task_fixture(5)


def _import_stopped(number: int, seconds: float, folder: Path | None) -> NoReturn:
    """Stop the import of task ``number``'s file, saying where it was (called by the time
    limit's signal handler, whose caller is the interrupted code)."""
    where = stuck_at(inspect.currentframe(), folder)
    raise TaskStopped(
        f"task{number}.py was still being imported after {seconds:g} s and was stopped"
        + (f" in {where}" if where else "")
        + "\nan endless loop at the top level of the file? (--call-timeout S allows more)"
    )


def check_arguments(
    check: Callable[..., Any], task: int, module: Any, numbers: own_numbers.Numbers
) -> dict[str, Any]:
    """The fixtures a graded check of ``task`` takes, as this plugin gives them, for a caller
    that calls the checks without pytest (``msdlab validate``): ``taskN`` (``module``) and
    ``own_numbers`` (``numbers``). A check that takes another is refused, naming it."""
    given = {f"task{task}": module, "own_numbers": numbers}
    taken = list(inspect.signature(check).parameters)
    unknown = [name for name in taken if name not in given]
    if unknown:
        raise TypeError(
            f"{check.__name__} takes {', '.join(unknown)}: a graded check of task {task} may "
            f"take only the fixtures {', '.join(given)}"
        )
    return {name: given[name] for name in taken}


@pytest.hookimpl(wrapper=True)
def pytest_runtest_setup(item: pytest.Item) -> Iterator[None]:
    """Set a check up (its fixtures import the task files) charged to its task's budget."""
    _start_check(item)
    with _charged(item):
        return (yield)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item) -> Iterator[None]:
    """Run a check charged to its task's budget."""
    with _charged(item):
        return (yield)


def _start_check(item: pytest.Item) -> None:
    """Each task's checks start afresh: a function that timed out in an earlier task runs
    again (in the same task it does not: it fails at once, `_explain` says where it did).
    The check's line goes to ``--msdlab-progress``."""
    graded = item.stash.get(_GRADED, None)
    task = graded[0] if graded else 0
    if item.config.stash.get(_LAST_TASK, None) != task:
        item.config.stash[_LAST_TASK] = task
        call_limit.forgive()
    progress = item.config.getoption("msdlab_progress")
    if graded and progress is not None:
        line = f"{task} {item.name.removeprefix('test_')}\n"  # runner.run_checks reads it
        with contextlib.suppress(OSError):
            os.write(progress, line.encode())


def _charged(item: pytest.Item) -> contextlib.AbstractContextManager:
    """The block whose student code is charged to its functions' budgets in ``item``'s task
    (nothing without a budget)."""
    graded = item.stash.get(_GRADED, None)
    budget = item.config.stash.get(_BUDGET, None)
    if graded is None or budget is None:
        return contextlib.nullcontext()
    return budget.charged(graded[0], item.name.removeprefix("test_"))


@pytest.hookimpl(tryfirst=True)  # before -m deselects: --msdlab-points counts every check
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Record task, points and hidden for each graded check; refuse checks without points."""
    problems = []
    for item in items:
        tasks = [n for n in TASKS if item.get_closest_marker(f"task{n}")]
        points = item.get_closest_marker("points")
        if not tasks:
            if points or item.get_closest_marker("hidden"):
                problems.append(f"{item.nodeid}: has points or hidden but no task marker")
            continue
        if len(tasks) > 1:
            problems.append(f"{item.nodeid}: belongs to several tasks {tasks}")
            continue
        value = points.args[0] if points and len(points.args) == 1 else None
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            problems.append(f"{item.nodeid}: needs @pytest.mark.points(N) with an integer N >= 1")
            continue
        item.stash[_GRADED] = (tasks[0], value, item.get_closest_marker("hidden") is not None)
    if problems:
        raise pytest.UsageError("graded checks are badly marked:\n  " + "\n  ".join(problems))
    path = config.getoption("msdlab_points")
    if path:
        graded = [item.stash[_GRADED] for item in items if _GRADED in item.stash]
        manifest.write(Path(path), graded)
    if any(_GRADED in item.stash for item in items):
        delegation.install()  # before the implementation is imported


def allowed_delegation(config: pytest.Config) -> set[int]:
    """The tasks named by ``--allow-delegation`` (e.g. "2,5")."""
    text = config.getoption("allow_delegation") or ""
    tasks = {part.strip().removeprefix("task") for part in text.split(",") if part.strip()}
    wrong = sorted(t for t in tasks if not t.isdigit() or int(t) not in TASKS)
    if wrong:
        raise pytest.UsageError(f"--allow-delegation takes task numbers {TASKS}, got {wrong}")
    return {int(t) for t in tasks}


@pytest.fixture(autouse=True)
def _own_implementation_only(request: pytest.FixtureRequest) -> Iterator[None]:
    """While a graded check runs, the engine's answer to its task refuses the
    implementation's calls (unless ``--allow-delegation`` names the task)."""
    graded = request.node.stash.get(_GRADED, None)
    if graded is None or graded[0] in allowed_delegation(request.config):
        yield
        return
    implementation = request.getfixturevalue("implementation")
    remote = getattr(implementation, "refuse_delegation", None)
    if remote is not None:  # the implementation runs in another process: it refuses there
        remote(graded[0])
        try:
            yield
        finally:
            remote(None)
        return
    with delegation.refusing(graded[0], getattr(implementation, "folder", None)):
        yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo):
    outcome = yield
    graded = item.stash.get(_GRADED, None)
    if graded is None:
        return
    report = outcome.get_result()
    results = item.config.stash[_REPORT].checks
    if report.when == "setup":
        results.append(_result(item, graded))
    result = results[-1]
    result.duration += report.duration
    if report.skipped:
        result.outcome, result.message = "skipped", _skip_reason(report)
    elif report.failed:
        result.outcome = "failed" if report.when == "call" else "error"
        result.exception, result.message, result.mistake = _describe(call, _task_folder(item))
        if call.excinfo is not None and isinstance(
            _stop_of(call.excinfo.value), call_limit.CallTimedOut
        ):
            result.message = _timed_out_once(result.message, item)
    elif report.when == "call":
        result.outcome = "passed"
    _stop_not_lost(item, result, report.when)


def _stop_not_lost(item: pytest.Item, result: CheckResult, when: str) -> None:
    """A check whose student code was stopped by its budget fails with what the stop said,
    even where something between the stop and pytest caught it."""
    budget = item.config.stash.get(_BUDGET, None)
    said = budget.said.get(item.name.removeprefix("test_")) if budget is not None else None
    if said and when == "call" and result.exception != TaskStopped.__name__:
        result.outcome, result.exception, result.message = "failed", TaskStopped.__name__, said


def pytest_sessionfinish(session: pytest.Session) -> None:
    config = session.config
    report = config.stash[_REPORT]
    report.duration = time.perf_counter() - config.stash[_STARTED]
    path = config.getoption("msdlab_report")
    if path:
        report.write(Path(path))


def pytest_terminal_summary(terminalreporter, config: pytest.Config) -> None:
    report = config.stash[_REPORT]
    if not report.checks:
        return
    parts = []
    for number in report.tasks():
        checks = [c for c in report.checks if c.task == number]
        earned, points = sum(c.earned for c in checks), sum(c.points for c in checks)
        parts.append(f"task{number} {earned}/{points}")
    terminalreporter.write_sep("-", "msdlab points")
    earned = f"{report.earned}/{report.points} points ({', '.join(parts)})"
    terminalreporter.write_line(f"{loader.describe(report.implementation)}: {earned}")


def _result(item: pytest.Item, graded: tuple[int, int, bool]) -> CheckResult:
    task, points, hidden = graded
    name = item.name.removeprefix("test_")
    # "error" until the check's call phase has run
    return CheckResult(item.nodeid, name, task, points, hidden, outcome="error")


def _describe(call: pytest.CallInfo, folder: Path | None) -> tuple[str | None, str, str]:
    """The exception's type name, its message in the course's words (where in the task files
    of ``folder`` it was raised, the input a property check failed on, each of the failures
    Hypothesis found) and the mistake the check recognised ('' if none)."""
    if call.excinfo is None:
        return None, "", ""
    error = _stop_of(call.excinfo.value)
    errors = getattr(error, "exceptions", None)  # an exception group (Python 3.10: a backport)
    if isinstance(errors, tuple) and len(errors) == 1:
        error, errors = errors[0], None
    if not isinstance(errors, tuple) or not errors:
        return type(error).__name__, _explain(error, folder), getattr(error, "mistake", "")
    kinds = {type(e).__name__ for e in errors}
    mistakes = {getattr(e, "mistake", "") for e in errors}
    lines = [f"it fails in {len(errors)} different ways:"]
    for number, each in enumerate(errors, 1):
        text = _explain(each, folder)
        text = text if len(kinds) == 1 else f"{type(each).__name__}: {text}"
        lines += [f"{number}. {line}" if i == 0 else f"   {line.strip()}"
                  for i, line in enumerate(text.splitlines())]  # fmt: skip
    kind = " and ".join(sorted(kinds))
    return kind, "\n".join(lines), mistakes.pop() if len(mistakes) == 1 else ""


def _stop_of(error: BaseException) -> BaseException:
    """``error``, or the stop it raised again where the student's code had caught it."""
    return error.__cause__ if isinstance(error, call_limit.StopIgnored) else error


def _explain(error: BaseException, folder: Path | None) -> str:
    """One exception's message in the course's words (see `_describe`)."""
    lines = [str(error).strip()]
    if isinstance(error, NotImplementedError):
        lines.append(failure.raised_in(error, folder, code=False))  # the function to write
    elif isinstance(error, call_limit.CallTimedOut):
        lines.append(failure.raised_in(error, folder).replace("in your code:", "stopped in"))
    elif not isinstance(error, TaskStopped):  # a stop says where it was
        lines.append(failure.raised_in(error, folder))
        lines += [failure.failing_inputs(str(note)) for note in getattr(error, "__notes__", ())]
    return "\n".join(line for line in lines if line)


def _timed_out_once(message: str, item: pytest.Item) -> str:
    """A timed-out call's ``message`` the first time in its task (with where the code was);
    in a later check, where the function was not called again, a line that points there."""
    stem, _, rest = message.partition(" (check ")
    first = item.config.stash[_TIMED_OUT].setdefault(stem, item.name.removeprefix("test_"))
    if first == item.name.removeprefix("test_") or not rest:
        return message
    return f"{stem} in check {first} and was not called again (see there)"


def _task_folder(item: pytest.Item) -> Path | None:
    """The folder of the task files under test, where they run in this process."""
    implementation = getattr(item, "funcargs", {}).get("implementation")
    return getattr(implementation, "folder", None)


def _skip_reason(report: pytest.TestReport) -> str:
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2]).removeprefix("Skipped: ")
    return str(longrepr or "")


def hypothesis_profiles(config: pytest.Config) -> None:
    """Register the ``ci`` and ``dev`` profiles; load ``ci`` unless a profile was chosen."""
    from hypothesis import settings

    settings.register_profile("ci", deadline=None, derandomize=True, database=None)
    settings.register_profile("dev", deadline=None)
    chosen = config.getoption("hypothesis_profile", None)
    if not chosen:
        settings.load_profile("ci")
