"""The result of a check run: one record per graded check, as JSON and as a text table.

The pytest plugin writes it (``--msdlab-report PATH``); ``msdlab check`` prints
it, and a grader can read many of them back with `CheckReport.read`.
JSON layout (``schema`` names the version)::

    {"schema": "msdlab-check-report/1", "implementation": "...", "duration": 3.2,
     "checks": [{"nodeid": "...", "name": "rest_state_feels_no_force", "task": 2,
                 "points": 2, "hidden": false, "outcome": "failed",
                 "exception": "NotImplementedError", "message": "Task 2: ...",
                 "duration": 0.01}, ...],
     "totals": {"points": 40, "earned": 12, "checks": 20, "passed": 6}}
"""

from __future__ import annotations

import json
import re
import textwrap
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
        first = self.message.strip().splitlines()[0] if self.message.strip() else ""
        if self.exception == "NotImplementedError":
            return "to do: " + re.sub(r"^Task \d+: ", "", first)
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
        that saw the same. A task whose checks all failed with the same message is one row.
        """
        if not self.checks:
            return "no graded checks ran"
        rows = _rows(self.checks)
        numbers = _numbers(rows, width)
        name_width = min(max(len(label) for label, _ in rows), max(width // 2, 30))
        message_width = max(width - name_width - 18, 20)
        lines = [f"{'check':<{name_width}}  points  result  message"]
        for label, checks in rows:
            first = checks[0]
            result = "pass" if first.passed else first.outcome.upper()
            message = ""
            if not first.passed:
                text = first.summary
                fits = len(text) <= message_width and _complete(first)
                message = text if fits else f"see [{numbers[_full_message(first)]}]"
            earned, points = sum(c.earned for c in checks), sum(c.points for c in checks)
            lines.append(
                f"{_shorten(label, name_width):<{name_width}}  {f'{earned}/{points}':>6}  "
                f"{result:<6}  {message}".rstrip()
            )
        passed = sum(check.passed for check in self.checks)
        count = len(self.checks)
        lines.append(
            f"total: {self.earned}/{self.points} points, {passed} of {count} checks passed"
        )
        return "\n".join(lines)

    def details(self, width: int = 100) -> str:
        """The full messages the table refers to as ``[n]``, each once."""
        rows = _rows(self.checks)
        numbers = _numbers(rows, width)
        blocks = []
        for message, number in numbers.items():
            body = "\n".join(
                textwrap.fill(line, width, initial_indent="  ", subsequent_indent="  ")
                for line in message.splitlines()
                if line.strip()
            )
            blocks.append(f"[{number}]\n{body}")
        return "\n\n".join(blocks)


def _rows(checks: list[CheckResult]) -> list[tuple[str, list[CheckResult]]]:
    """(label, checks) per table row: one per check, or one for a whole task whose checks
    all failed with the same message."""
    rows: list[tuple[str, list[CheckResult]]] = []
    tasks = sorted({c.task for c in checks})
    for task in tasks:
        group = [c for c in checks if c.task == task]
        same = {(c.outcome, _full_message(c)) for c in group}
        if len(group) > 1 and len(same) == 1 and not group[0].passed:
            hidden = " incl. hidden" if any(c.hidden for c in group) else ""
            rows.append((f"task{task} (all {len(group)} checks{hidden})", group))
        else:
            rows += [(_label(c), [c]) for c in group]
    order = {id(c): i for i, c in enumerate(checks)}
    return sorted(rows, key=lambda row: order[id(row[1][0])])


def _numbers(rows: list[tuple[str, list[CheckResult]]], width: int) -> dict[str, int]:
    """Full message -> its number, for the failing rows whose message does not fit."""
    name_width = min(max(len(label) for label, _ in rows), max(width // 2, 30)) if rows else 0
    message_width = max(width - name_width - 18, 20)
    numbers: dict[str, int] = {}
    for _, checks in rows:
        first = checks[0]
        if first.passed:
            continue
        full = _full_message(first)
        if len(first.summary) <= message_width and _complete(first):
            continue
        numbers.setdefault(full, len(numbers) + 1)
    return numbers


def _complete(check: CheckResult) -> bool:
    """Whether the table's one-line summary of a check says all its message does."""
    return "\n" not in check.message.strip()


def _label(check: CheckResult) -> str:
    hidden = " (hidden)" if check.hidden else ""
    return f"task{check.task} {check.name}{hidden}"


def _full_message(check: CheckResult) -> str:
    if check.exception == "NotImplementedError":
        return "to do: " + re.sub(r"^Task \d+: ", "", check.message.strip())
    if check.exception and check.exception not in ("CheckFailed", "AssertionError"):
        return f"{check.exception}: {check.message}"
    return check.message or "(no message)"


def _shorten(text: str, width: int) -> str:
    """``text`` cut to ``width`` characters with "…", keeping a " (hidden)" mark whole."""
    if len(text) <= width:
        return text
    mark = " (hidden)" if text.endswith(" (hidden)") else ""
    return text[: width - 1 - len(mark)] + "…" + mark
