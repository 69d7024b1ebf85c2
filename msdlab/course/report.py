"""The result of a check run: one record per graded check, as JSON and as a text table.

The pytest plugin writes it (``--msdlab-report PATH``); ``msdlab check`` prints
it, and a grader can read many of them back with `CheckReport.read`.
JSON layout (``schema`` names the version)::

    {"schema": "msdlab-check-report/1", "implementation": "...", "duration": 3.2,
     "checks": [{"nodeid": "...", "name": "rest_state_feels_no_force", "task": 2,
                 "points": 2, "hidden": false, "outcome": "failed",
                 "exception": "NotImplementedError", "message": "Task 2: ...",
                 "duration": 0.01, "mistake": ""}, ...],
     "totals": {"points": 40, "earned": 12, "checks": 20, "passed": 6}}
"""

from __future__ import annotations

import json
import re
import textwrap
from collections import Counter
from dataclasses import asdict, dataclass, field
from pathlib import Path

SCHEMA = "msdlab-check-report/1"


@dataclass
class CheckResult:
    """One graded check: where it is, what it is worth, and how it went.

    ``outcome`` is 'passed', 'failed' (the check saw wrong results, or the
    submission raised), 'error' (it could not run, e.g. the task file does not
    import) or 'skipped'. ``message`` says what was seen, in physics terms.
    """

    nodeid: str
    name: str
    task: int
    points: int
    hidden: bool
    outcome: str
    exception: str | None = None
    message: str = ""
    duration: float = 0.0
    mistake: str = ""

    @property
    def passed(self) -> bool:
        return self.outcome == "passed"

    @property
    def earned(self) -> int:
        return self.points if self.passed else 0

    @property
    def summary(self) -> str:
        """The first line of the message: what is still to do, or the exception raised and its
        message, or what the check saw."""
        if self.exception == "NotImplementedError":
            return to_do(self.message)
        first = self.message.strip().splitlines()[0] if self.message.strip() else ""
        if self.exception and self.exception not in ("CheckFailed", "AssertionError"):
            return f"{self.exception}: {first}" if first else self.exception
        return first


@dataclass
class CheckReport:
    """All graded checks of one run against one implementation."""

    implementation: str
    checks: list[CheckResult] = field(default_factory=list)
    duration: float = 0.0

    @property
    def points(self) -> int:
        return sum(check.points for check in self.checks)

    @property
    def earned(self) -> int:
        return sum(check.earned for check in self.checks)

    @property
    def all_passed(self) -> bool:
        return bool(self.checks) and all(check.passed for check in self.checks)

    def tasks(self) -> list[int]:
        return sorted({check.task for check in self.checks})

    def to_dict(self) -> dict:
        return {
            "schema": SCHEMA,
            "implementation": self.implementation,
            "duration": round(self.duration, 3),
            "checks": [asdict(check) for check in self.checks],
            "totals": {
                "points": self.points,
                "earned": self.earned,
                "checks": len(self.checks),
                "passed": sum(check.passed for check in self.checks),
            },
        }

    def write(self, path: Path) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(self.to_dict(), indent=2) + "\n", encoding="utf-8")

    @classmethod
    def read(cls, path: Path) -> CheckReport:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        if data.get("schema") != SCHEMA:
            raise ValueError(f"{path} is not a {SCHEMA} report (schema {data.get('schema')!r})")
        checks = [CheckResult(**check) for check in data["checks"]]
        return cls(data["implementation"], checks, data.get("duration", 0.0))

    def table(self, width: int = 100) -> str:
        """Check, points, result and message of every check, then the totals.

        A failing check's message is in the table when it fits on its row, else the row
        says ``see [n]`` and `details` prints message n in full, once for all the checks
        that saw the same: one error raised in several checks, or one mistake recognised
        by several (`CheckResult.mistake`). A task whose checks all failed with the same
        message is one row.
        """
        if not self.checks:
            return "no graded checks ran"
        rows = _rows(self.checks)
        numbers = _numbers(rows, width)
        name_width = _name_width(rows, width)
        lines = [f"{'check':<{name_width}}  points  result  message"]
        for label, checks in rows:
            first = checks[0]
            result = "pass" if first.passed else first.outcome.upper()
            topic = _topic(first)
            message = f"see [{numbers[topic]}]" if topic in numbers else first.summary
            earned, points = sum(c.earned for c in checks), sum(c.points for c in checks)
            lines.append(
                f"{_shorten(label, name_width):<{name_width}}  {f'{earned}/{points}':>6}  "
                f"{result:<6}  {message if not first.passed else ''}".rstrip()
            )
        passed = sum(check.passed for check in self.checks)
        count = len(self.checks)
        lines.append(
            f"total: {self.earned}/{self.points} points, {passed} of {count} checks passed"
        )
        return "\n".join(lines)

    def score_line(self, hidden_worth: int = 0) -> str:
        """'public P of Q points; hidden checks worth H more run when graded' (or the hidden
        score when they ran)."""
        public = [c for c in self.checks if not c.hidden]
        hidden = [c for c in self.checks if c.hidden]
        line = f"public {sum(c.earned for c in public)} of {sum(c.points for c in public)} points"
        if hidden:
            earned, points = sum(c.earned for c in hidden), sum(c.points for c in hidden)
            return f"{line}; hidden {earned} of {points} points"
        if hidden_worth:
            return f"{line}; hidden checks worth {hidden_worth} more run when graded"
        return line

    def printout(self, width: int = 100, hidden_worth: int = 0) -> str:
        """What ``msdlab check`` and a notebook's check cell show: the table, the score line
        and the messages the table refers to, in full."""
        details = self.details(width)
        parts = [self.table(width), self.score_line(hidden_worth)]
        return "\n".join(parts + (["", "in full:", "", details] if details else []))

    def details(self, width: int = 100) -> str:
        """The full messages the table refers to as ``[n]``, each once: a recognised mistake
        named once, with what each check that follows from it saw."""
        rows = _rows(self.checks)
        numbers = _numbers(rows, width)
        failing = [checks for _, checks in rows if not checks[0].passed]
        blocks = []
        for topic, number in numbers.items():
            group = [c for checks in failing for c in checks if _topic(c) == topic]
            blocks.append(f"[{number}]\n" + _wrapped(_explained(group), width))
        return "\n\n".join(blocks)


def _rows(checks: list[CheckResult]) -> list[tuple[str, list[CheckResult]]]:
    """(label, checks) per table row: one per check, or one for a whole task whose checks
    all failed with the same message."""
    rows: list[tuple[str, list[CheckResult]]] = []
    tasks = sorted({c.task for c in checks})
    for task in tasks:
        group = [c for c in checks if c.task == task]
        same = {(c.outcome, _topic(c)) for c in group}
        if len(group) > 1 and len(same) == 1 and not group[0].passed and not group[0].mistake:
            hidden = " incl. hidden" if any(c.hidden for c in group) else ""
            rows.append((f"task{task} (all {len(group)} checks{hidden})", group))
        else:
            rows += [(_label(c), [c]) for c in group]
    order = {id(c): i for i, c in enumerate(checks)}
    return sorted(rows, key=lambda row: order[id(row[1][0])])


def _name_width(rows: list[tuple[str, list[CheckResult]]], width: int) -> int:
    return min(max(len(label) for label, _ in rows), max(width // 2, 30)) if rows else 0


def _numbers(rows: list[tuple[str, list[CheckResult]]], width: int) -> dict[str, int]:
    """Topic -> its number, for the failing rows whose message is printed below the table:
    it does not fit on its row, or other rows share it."""
    message_width = max(width - _name_width(rows, width) - 18, 20)
    failing = [checks[0] for _, checks in rows if not checks[0].passed]
    shared = Counter(_topic(check) for check in failing)
    numbers: dict[str, int] = {}
    for check in failing:
        topic = _topic(check)
        fits = len(check.summary) <= message_width and _complete(check)
        if shared[topic] > 1 or not fits:
            numbers.setdefault(topic, len(numbers) + 1)
    return numbers


def _topic(check: CheckResult) -> str:
    """What a failing check's row refers to: the mistake it recognised (one per task), an
    error by the line of the student's file that raised it (one row for one error, whatever
    the inputs and shapes of each check), else its full message."""
    if check.mistake:
        return f"task {check.task}: {check.mistake}"
    message = _full_message(check)
    if _is_error(check):
        where = [line for line in message.splitlines() if line.startswith(WHERE)]
        return f"{check.exception} {where[0]}" if where else _without_inputs(message)
    return message


def _is_error(check: CheckResult) -> bool:
    """Whether the check stopped at an error (not at a failed expectation or a to-do)."""
    return check.exception not in (None, "CheckFailed", "AssertionError", "NotImplementedError")


def _without_inputs(message: str) -> str:
    return "\n".join(line for line in message.splitlines() if not _is_input(line))


def _explained(group: list[CheckResult]) -> str:
    """The text of one topic: the recognised mistake once and what each check saw, or the
    message once and the inputs each check failed on."""
    first = group[0]
    if first.mistake:
        lines = [f"{MISTAKE_HEADING}{first.mistake}."]
        for check in group:
            saw = without_mistake(check.message, check.mistake)
            lines.append(f"{check.name}{' (hidden)' if check.hidden else ''}: {saw}")
        return "\n".join(lines)
    lines = [_without_inputs(_full_message(first))]
    for check in group:
        inputs = [line for line in _full_message(check).splitlines() if _is_input(line)]
        if inputs:
            lines.append(f"{check.name}: {'; '.join(inputs)}" if len(group) > 1 else inputs[0])
    return "\n".join(lines)


MISTAKE_HEADING = "recognised mistake: "
"""How `details` names a mistake a check recognised; the check's message says it as
``MISTAKE_SENTENCE``."""
MISTAKE_SENTENCE = "Your result is exactly what this mistake gives: {}."
"""The sentence `msdlab.course.feedback.expect` ends a message with where a check recognised
the mistake (not merely its usual cause)."""


def without_mistake(message: str, mistake: str) -> str:
    """``message`` without its sentence naming ``mistake``: what the check saw."""
    return " ".join(message.replace(MISTAKE_SENTENCE.format(mistake), "").split())


def _is_input(line: str) -> bool:
    """Whether ``line`` says which generated input a property check failed on."""
    starts = ("the input that failed", "the inputs that failed", "it fails whatever")
    return line.strip().startswith(starts)


def _wrapped(text: str, width: int) -> str:
    return "\n".join(
        textwrap.fill(line, width, initial_indent="  ", subsequent_indent="  ")
        for line in text.splitlines()
        if line.strip()
    )


def _complete(check: CheckResult) -> bool:
    """Whether the table's one-line summary of a check says all its message does."""
    return "\n" not in check.message.strip()


def _label(check: CheckResult) -> str:
    hidden = " (hidden)" if check.hidden else ""
    return f"task{check.task} {check.name}{hidden}"


def _full_message(check: CheckResult) -> str:
    if check.exception == "NotImplementedError":
        return to_do(check.message)
    if check.exception and check.exception not in ("CheckFailed", "AssertionError"):
        return f"{check.exception}: {check.message}"
    return check.message or "(no message)"


def to_do(message: str) -> str:
    """A template's "Task 2: sum eq. (1.2) ..." with the line "in your code: FILE, line L, in
    FUNCTION" as 'to do in FILE, FUNCTION: sum eq. (1.2) ...' (where to edit, and what)."""
    text, _, where = message.strip().partition(f"\n{WHERE}")
    text = " ".join(re.sub(r"^Task \d+: ", "", text).split())
    found = re.match(r"(?P<file>.+), line \d+, in (?P<function>\S+)", where)
    return f"to do in {found['file']}, {found['function']}: {text}" if found else f"to do: {text}"


WHERE = "in your code: "
"""How a message names the line of the student's file where it was raised
(`msdlab.course.failure.raised_in`)."""


def _shorten(text: str, width: int) -> str:
    """``text`` cut to ``width`` characters with "…", keeping a " (hidden)" mark whole."""
    if len(text) <= width:
        return text
    mark = " (hidden)" if text.endswith(" (hidden)") else ""
    return text[: width - 1 - len(mark)] + "…" + mark
