"""How strong is a check set? Run it on the solutions, the templates and mutants of the solutions.

The checks of a task (``test_taskN.py`` and ``test_taskN_hidden.py``) are run here, in this
process, on any version of the task's file (`run_checks`): each check is called with the
task module, under the same refusal of delegation as in pytest (`msdlab.course.delegation`)
and a time limit. `validate` runs them on

- the solution: every check must pass;
- the template: every check must fail (a check a template passes gives points for nothing);
- trivial answers (`msdlab.instructor.trivial`): the solution answering zeros, its input,
  constants, NaN, inf, empty or complex arrays; every check must fail (no point for nothing);
- mutants of the solution (`mutants`): small changes to the code inside the solution blocks
  (operators, operands, constants, comparisons, dropped terms, signs). A mutant is *killed*
  when a check fails on it; the report names, per check, the mutants it alone kills, and
  lists the survivors: each is equivalent to the solution, with the one-line reason given in
  ``solutions/equivalent_mutants.json`` (`EQUIVALENT_FILE`), or a mistake no check catches.
  A mutant runs only the checks that reach the function it changes (`reached`).

Mutation tools such as mutmut mutate a whole package and report per test-suite run; a
per-check kill matrix of a single file's solution blocks, judged by checks that take the
module as a fixture, is simpler to make here with `ast` than to extract from them.
"""

from __future__ import annotations

import ast
import contextlib
import dataclasses
import importlib.util
import json
import random
import shutil
import sys
import tempfile
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any, NoReturn

import numpy as np

from ..course import call_limit, delegation, own_numbers
from ..course.loader import FolderImplementation
from ..course.pytest_plugin import check_arguments
from . import trivial

BEGIN, END = "### BEGIN SOLUTION", "### END SOLUTION"
EQUIVALENT_FILE = "equivalent_mutants.json"
"""In ``solutions/``: ``{"taskN": {"function: old -> new": "why it computes the same"}}``,
the instructor's claim for each surviving mutant; a key ``function: <the line's code>``
claims every mutant of that line."""


@dataclass(frozen=True)
class Check:
    """A graded check: its name (without ``test_``), task, points and function."""

    name: str
    task: int
    points: int
    hidden: bool
    function: Callable[..., Any]


@dataclass(frozen=True)
class Outcome:
    """What a check said about one version of a task file."""

    passed: bool
    exception: str = ""
    message: str = ""


@dataclass(frozen=True)
class Mutant:
    """The solution with one change: where, what was there, what is there now."""

    task: int
    line: int
    old: str
    new: str
    source: str
    original: str
    place: str = ""  # "2nd of 3 on the line" when ``old`` occurs more than once on its line

    @property
    def change(self) -> str:
        """``old -> new``, with the `place` of ``old`` if the line holds it more than once."""
        return f"{self.old} -> {self.new}" + (f" ({self.place})" if self.place else "")

    @property
    def label(self) -> str:
        return f"line {self.line}: {self.change}"

    def claims(self) -> tuple[str, str]:
        """How `EQUIVALENT_FILE` names it (no line number): ``function: old -> new`` (with
        its place, e.g. ``(2nd of 3 on the line)``, if ``old`` occurs more than once on the
        line), and ``function: <the line's code>`` for all mutants of its line."""
        function = definition_at(self.source, self.line)
        line = self.original_line.strip()
        return f"{function}: {self.change}", f"{function}: {line}"

    @property
    def original_line(self) -> str:
        return self.original.splitlines()[self.line - 1]


@dataclass
class TaskReport:
    """The result of `validate` for one task."""

    task: int
    checks: list[str]
    solution_failures: dict[str, Outcome] = field(default_factory=dict)
    template_passes: list[str] = field(default_factory=list)
    kills: dict[str, list[str]] = field(default_factory=dict)  # mutant label -> checks
    mutants: int = 0
    trivial_paid: dict[str, list[str]] = field(default_factory=dict)  # kind -> checks passed
    equivalent: dict[str, str] = field(default_factory=dict)  # survivor label -> reason

    @property
    def survivors(self) -> list[str]:
        return [label for label, checks in self.kills.items() if not checks]

    @property
    def unexplained(self) -> list[str]:
        """The survivors not claimed equivalent: mistakes that no check catches."""
        return [label for label in self.survivors if label not in self.equivalent]

    @property
    def kill_rate(self) -> float:
        """Killed mutants among those not equivalent to the solution."""
        counted = self.mutants - len(self.survivors) + len(self.unexplained)
        return 1.0 - len(self.unexplained) / counted if counted else 1.0

    def alone(self, check: str) -> list[str]:
        """The mutants that ``check`` alone kills."""
        return [label for label, checks in self.kills.items() if checks == [check]]


# ---------------------------------------------------------------------------- running checks
def collect_checks(checks: Path, task: int) -> list[Check]:
    """The graded checks of ``task`` in the folder ``checks`` (public and hidden), under the
    validation's hypothesis profile (loaded first: a check's ``@settings`` copies it)."""
    _hypothesis_profile()
    found = []
    folder = str(Path(checks).resolve())
    if folder not in sys.path:
        sys.path.insert(0, folder)  # the hidden checks import their references by name
    for suffix, hidden in (("", False), ("_hidden", True)):
        path = Path(checks) / f"test_task{task}{suffix}.py"
        if not path.is_file():
            continue
        module = _import(path, f"msdlab_validate_checks_task{task}{suffix}")
        for name, function in vars(module).items():
            if not (name.startswith("test_") and callable(function)):
                continue
            marks = [*_marks(module), *_marks(function)]
            points = next((m.args[0] for m in marks if m.name == "points"), None)
            if points is not None:
                found.append(Check(name.removeprefix("test_"), task, points, hidden, function))
    return found


def run_checks(
    checks: Sequence[Check],
    module: Any,
    folder: Path | None,
    *,
    seconds: float = 30.0,
    stop_at_first_failure: bool = False,
    numbers: own_numbers.Numbers = own_numbers.DEFAULT,
) -> dict[str, Outcome]:
    """Each check's `Outcome` on ``module`` (a task module loaded from ``folder``), called
    in this process with the fixtures the course's pytest plugin gives (`check_arguments`:
    the template's own numbers unless a student's ``numbers``), its refusal of delegation
    and a time limit."""
    outcomes: dict[str, Outcome] = {}
    for check in checks:
        try:
            with (
                delegation.refusing(check.task, folder),
                _time_limit(seconds),
                warnings.catch_warnings(),  # mutants overflow and divide by zero a lot
                np.errstate(all="ignore"),
            ):
                warnings.simplefilter("ignore")
                check.function(**check_arguments(check.function, check.task, module, numbers))
        except (KeyboardInterrupt, SystemExit):
            raise
        except BaseException as error:  # whatever the code under test raises
            outcomes[check.name] = Outcome(False, type(error).__name__, _message(error))
            if stop_at_first_failure:
                break
        else:
            outcomes[check.name] = Outcome(True)
    return outcomes


def run_source(
    source: str, task: int, checks: Sequence[Check], **options: Any
) -> dict[str, Outcome]:
    """`run_checks` on a task file given as text (written to a fresh folder and imported)."""
    with _task_file(source, task) as (module, folder, failure):
        if failure is not None:  # a version that does not even import fails every check
            return {check.name: failure for check in checks}
        return run_checks(checks, module, folder, **options)


def reached(
    source: str,
    task: int,
    checks: Sequence[Check],
    outcomes: dict[str, Outcome] | None = None,
    **options: Any,
) -> dict[str, set]:
    """Per check, the top-level functions and classes of the task file it can reach.

    The checks are run on ``source`` (the solution) with a module that records which of
    its names each check uses; the file's own calls between its functions are added, so
    a change inside a function matters only to the checks listed with it. The checks'
    outcomes on ``source`` go to ``outcomes`` if given.
    """
    calls = _calls_between_definitions(source)
    used: dict[str, set] = {}
    with _task_file(source, task) as (module, folder, failure):
        if failure is not None:
            raise ValueError(f"task{task}.py does not import: {failure.message}")
        for check in checks:
            recorder = _Recorder(module)
            (outcomes if outcomes is not None else {}).update(
                run_checks([check], recorder, folder, **options)
            )
            found, todo = set(), list(recorder.names)
            while todo:
                name = todo.pop()
                if name not in found:
                    found.add(name)
                    todo += calls.get(name, ())
            used[check.name] = found
    return used


def definition_at(source: str, line: int) -> str | None:
    """The name of the top-level function or class whose code holds ``line``."""
    for node in ast.parse(source).body:
        inside = node.lineno <= line <= (getattr(node, "end_lineno", None) or node.lineno)
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and inside:
            return node.name
    return None


class _Recorder:
    """A task module that notes the names the checks take from it."""

    def __init__(self, module: Any) -> None:
        self._module, self.names = module, set()

    def __getattr__(self, name: str) -> Any:
        self.names.add(name)
        return getattr(self._module, name)


def _calls_between_definitions(source: str) -> dict[str, set[str]]:
    """For each top-level function or class: the file's other top-level names it uses."""
    tree = ast.parse(source)
    defined = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    return {
        node.name: {n.id for n in ast.walk(node) if isinstance(n, ast.Name) and n.id in defined}
        - {node.name}
        for node in tree.body
        if isinstance(node, (ast.FunctionDef, ast.ClassDef))
    }


@contextlib.contextmanager
def _task_file(source: str, task: int) -> Iterator[tuple[Any, Path, Outcome | None]]:
    """The task module made from ``source`` in a fresh folder (or why it does not import)."""
    folder = Path(tempfile.mkdtemp(prefix="msdlab-validate-"))
    try:
        (folder / f"task{task}.py").write_text(source)
        try:
            module = FolderImplementation(folder).task(task)
        except Exception as error:
            yield None, folder, Outcome(False, type(error).__name__, _message(error))
        else:
            yield module, folder, None
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _marks(holder: object) -> list[Any]:
    marks = getattr(holder, "pytestmark", [])
    marks = marks if isinstance(marks, list) else [marks]
    return [getattr(mark, "mark", mark) for mark in marks]


def _import(path: Path, name: str) -> ModuleType:
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load the checks {path}")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _message(error: BaseException) -> str:
    lines = [str(error).strip()] if str(error).strip() else []
    lines += [str(n) for n in getattr(error, "__notes__", ()) if str(n).startswith("Falsifying")]
    return "\n".join(lines)


def _hypothesis_profile() -> None:
    """The checks' reproducible profile, without hypothesis's own failure printouts."""
    from hypothesis import Verbosity, settings

    settings.register_profile(
        "msdlab-validate",
        deadline=None,
        derandomize=True,
        database=None,
        verbosity=Verbosity.quiet,
    )
    settings.load_profile("msdlab-validate")


class CheckTimeout(BaseException):
    """A check ran longer than its time limit (an endless loop in the code under test?).

    Not an `Exception`, so that hypothesis does not catch it and shrink an endless example.
    """


def _time_limit(seconds: float) -> contextlib.AbstractContextManager[None]:
    """Interrupt the block after ``seconds`` (main thread only; elsewhere no limit)."""

    def expire() -> NoReturn:
        raise CheckTimeout(f"no answer within {seconds:g} s (an endless loop?)")

    return call_limit.time_limit(seconds, expire)


# ---------------------------------------------------------------------------------- mutants
_SWAPPED_OPERATORS = {
    ast.Add: ast.Sub, ast.Sub: ast.Add, ast.Mult: ast.Div, ast.Div: ast.Mult,
    ast.Pow: ast.Mult, ast.FloorDiv: ast.Div, ast.Mod: ast.FloorDiv,
}  # fmt: skip
_SWAPPED_COMPARISONS = {
    ast.Lt: ast.LtE, ast.LtE: ast.Lt, ast.Gt: ast.GtE, ast.GtE: ast.Gt,
    ast.Eq: ast.NotEq, ast.NotEq: ast.Eq, ast.In: ast.NotIn, ast.NotIn: ast.In,
}  # fmt: skip
_NOT_COMMUTATIVE = (ast.Sub, ast.Div, ast.MatMult, ast.Pow, ast.FloorDiv, ast.Mod)


def solution_lines(source: str) -> set[int]:
    """The line numbers (1-based) inside the solution blocks of a task file."""
    lines, inside = set(), False
    for number, text in enumerate(source.splitlines(), start=1):
        if BEGIN in text:
            inside = True
        elif END in text:
            inside = False
        elif inside:
            lines.add(number)
    return lines


def mutants(source: str, task: int) -> list[Mutant]:
    """Every single-change mutant of the code in the solution blocks of ``source``."""
    inside = solution_lines(source)
    found: dict[tuple[int, int, str], Mutant] = {}
    for node in ast.walk(ast.parse(source)):
        if getattr(node, "lineno", None) not in inside or node.lineno != node.end_lineno:
            continue
        for replacement in _replacements(node):
            new = ast.unparse(replacement)
            old = ast.get_source_segment(source, node) or ""
            if not old or new == ast.unparse(node):
                continue
            key = (node.lineno, node.col_offset, new)
            if key not in found:
                changed = _replace(source, node, new)
                found[key] = Mutant(task, node.lineno, old, new, changed, source)
    # The same text at several places of a line ("0" in (0, 0, 0)) makes mutants with the
    # same "old -> new": each is told apart by its place, so none hides another's outcome.
    columns: dict[tuple[int, str], set[int]] = {}
    for (line, column, _), mutant in found.items():
        columns.setdefault((line, mutant.old), set()).add(column)
    for (line, column, new), mutant in found.items():
        places = sorted(columns[(line, mutant.old)])
        if len(places) > 1:
            place = f"{_ordinal(places.index(column) + 1)} of {len(places)} on the line"
            found[(line, column, new)] = dataclasses.replace(mutant, place=place)
    return sorted(found.values(), key=lambda m: (m.line, m.old, m.place, m.new))


def _ordinal(number: int) -> str:
    suffix = "th" if 10 <= number % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(number % 10)
    return f"{number}{suffix or 'th'}"


def _replacements(node: ast.AST) -> Iterator[ast.AST]:
    """The mutations of one node (new nodes; the original is left alone)."""
    if isinstance(node, ast.BinOp):
        swapped = _SWAPPED_OPERATORS.get(type(node.op))
        if swapped is not None:
            yield ast.BinOp(node.left, swapped(), node.right)
        if isinstance(node.op, _NOT_COMMUTATIVE):
            yield ast.BinOp(node.right, node.op, node.left)
        if isinstance(node.op, (ast.Add, ast.Sub)):  # a dropped term
            yield node.left
            yield node.right
        if isinstance(node.op, (ast.Mult, ast.Div)):  # a dropped factor
            yield node.left
    elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        yield node.operand
    elif isinstance(node, ast.Compare) and len(node.ops) == 1:
        swapped = _SWAPPED_COMPARISONS.get(type(node.ops[0]))
        if swapped is not None:
            yield ast.Compare(node.left, [swapped()], node.comparators)
    elif isinstance(node, ast.AugAssign):
        swapped = _SWAPPED_OPERATORS.get(type(node.op))
        if swapped is not None:
            yield ast.AugAssign(node.target, swapped(), node.value)
    elif isinstance(node, ast.Constant) and type(node.value) in (int, float):
        yield ast.Constant(node.value + 1)
        yield ast.Constant(node.value - 1)
        if isinstance(node.value, float) and node.value not in (0.0, 1.0):
            yield ast.Constant(node.value * 2)
    elif isinstance(node, ast.Constant) and isinstance(node.value, bool):
        yield ast.Constant(not node.value)


def _replace(source: str, node: ast.AST, new: str) -> str:
    """``source`` with the text of ``node`` (one line; offsets in UTF-8 bytes) replaced."""
    lines = source.splitlines(keepends=True)
    line = lines[node.lineno - 1].encode()
    text = line[: node.col_offset] + new.encode() + line[node.end_col_offset :]
    lines[node.lineno - 1] = text.decode()
    return "".join(lines)


# --------------------------------------------------------------------------------- the report
def validate(
    course: Path,
    tasks: Sequence[int],
    *,
    sample: int | None = None,
    seed: int = 0,
    seconds: float = 30.0,
    progress: Callable[[str], None] | None = None,
) -> list[TaskReport]:
    """Run the checks of ``tasks`` on the solutions, the templates and mutants (see module).

    ``course`` holds ``solutions/``, ``assignments/`` and ``tests/tasks/``; ``sample``
    limits the mutants per task to a random sample of that size (``seed``).
    """
    course = Path(course)
    reports = []
    delegation.install()
    for task in tasks:
        checks = collect_checks(course / "tests" / "tasks", task)
        source = (course / "solutions" / f"task{task}.py").read_text()
        report = TaskReport(task, [c.name for c in checks])
        solved: dict[str, Outcome] = {}
        uses = reached(source, task, checks, solved, seconds=seconds)
        report.solution_failures = {n: o for n, o in solved.items() if not o.passed}
        template = course / "assignments" / f"task{task}.py"
        if template.is_file():
            outcomes = run_source(template.read_text(), task, checks, seconds=seconds)
            report.template_passes = [n for n, o in outcomes.items() if o.passed]
        for kind in trivial.KINDS:
            outcomes = run_source(
                trivial.answer_source(source, kind), task, checks, seconds=seconds
            )
            report.trivial_paid[kind] = [n for n, o in outcomes.items() if o.passed]
        chosen = mutants(source, task)
        if sample is not None and sample < len(chosen):
            chosen = sorted(random.Random(seed).sample(chosen, sample), key=lambda m: m.line)
        report.mutants = len(chosen)
        reasons = equivalence_reasons(course / "solutions" / EQUIVALENT_FILE, task)
        for number, mutant in enumerate(chosen, start=1):
            changed = definition_at(source, mutant.line)
            concerned = [c for c in checks if changed is None or changed in uses[c.name]]
            outcomes = run_source(mutant.source, task, concerned, seconds=seconds)
            report.kills[mutant.label] = [n for n, o in outcomes.items() if not o.passed]
            reason = next((reasons[k] for k in mutant.claims() if k in reasons), None)
            if not report.kills[mutant.label] and reason is not None:
                report.equivalent[mutant.label] = reason
            if progress is not None:
                progress(f"task {task}: mutant {number}/{len(chosen)} {mutant.label}")
        reports.append(report)
    return reports


def equivalence_reasons(path: Path, task: int) -> dict[str, str]:
    """``function: old -> new`` -> why that mutant computes the same, from `EQUIVALENT_FILE`."""
    if not path.is_file():
        return {}
    return dict(json.loads(path.read_text(encoding="utf-8")).get(f"task{task}", {}))


def format_report(reports: Sequence[TaskReport], verbose: bool = False) -> str:
    """The instructor's text: per task the solution, template and trivial answers' verdicts,
    the kills of each check (and the mutants it alone kills), the survivors with reasons."""
    out = []
    for report in reports:
        out.append(f"task {report.task}: {len(report.checks)} checks, {report.mutants} mutants")
        out.append(f"  solution: {_solution_verdict(report)}")
        template = (
            "all fail"
            if not report.template_passes
            else "PASSES: " + ", ".join(report.template_passes)
        )
        out.append(f"  template: {template}")
        out += _trivial_lines(report)
        out += _kill_lines(report, verbose)
        out += _survivor_lines(report)
    total = sum(r.mutants - len(r.survivors) + len(r.unexplained) for r in reports)
    missed = sum(len(r.unexplained) for r in reports)
    if total:
        out.append(
            f"all tasks: {total - missed}/{total} non-equivalent mutants killed "
            f"({1 - missed / total:.0%})"
        )
    return "\n".join(out)


def broken(report: TaskReport) -> bool:
    """A solution fails, a template passes, or a trivial answer earns a point."""
    return bool(
        report.solution_failures or report.template_passes or any(report.trivial_paid.values())
    )


def _solution_verdict(report: TaskReport) -> str:
    if not report.solution_failures:
        return "all pass"
    return "FAIL: " + ", ".join(
        f"{n} ({o.exception}: {o.message.splitlines()[0] if o.message else ''})"
        for n, o in report.solution_failures.items()
    )


def _trivial_lines(report: TaskReport) -> list[str]:
    if not report.trivial_paid:
        return []
    paid = {kind: checks for kind, checks in report.trivial_paid.items() if checks}
    kinds = ", ".join(report.trivial_paid)
    if not paid:
        return [f"  trivial answers ({kinds}): every check fails, 0 points"]
    return [f"  trivial answers: PAID {kind} by {', '.join(c)}" for kind, c in paid.items()]


def _kill_lines(report: TaskReport, verbose: bool) -> list[str]:
    killers: dict[str, int] = dict.fromkeys(report.checks, 0)
    for checks in report.kills.values():
        for name in checks:
            killers[name] += 1
    out = ["  mutants killed per check (alone: killed by no other check):"]
    for name in report.checks:
        alone = report.alone(name)
        out.append(f"    {killers[name]:4d}  {name} ({len(alone)} alone)")
        out += [f"            alone: {label}" for label in alone]
    if verbose:
        out.append("  kills:")
        out += [f"    {label}: {', '.join(c)}" for label, c in report.kills.items() if c]
    return out


def _survivor_lines(report: TaskReport) -> list[str]:
    out = [f"  survivors equivalent to the solution ({len(report.equivalent)}):"]
    out += [f"    {label}: {reason}" for label, reason in report.equivalent.items()]
    out.append(f"  survivors no check catches ({len(report.unexplained)}):")
    out += [f"    {label}" for label in report.unexplained]
    out.append(f"  kill rate: {report.kill_rate:.0%} of the mutants not equivalent to the solution")
    return out
