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
        """Check, points, result and the short message of every check, then the totals."""
        if not self.checks:
            return "no graded checks ran"
        name_width = min(max(len(_label(c)) for c in self.checks), max(width // 2, 30))
        message_width = max(width - name_width - 17, 20)
        lines = [f"{'check':<{name_width}}  points  result  message"]
        for check in self.checks:
            result = "pass" if check.passed else check.outcome.upper()
            message = "" if check.passed else _shorten(check.summary, message_width)
            points = f"{check.earned}/{check.points}"
            lines.append(
                f"{_shorten(_label(check), name_width):<{name_width}}  {points:>6}  "
                f"{result:<6}  {message}".rstrip()
            )
        passed = sum(check.passed for check in self.checks)
        count = len(self.checks)
        lines.append(
            f"total: {self.earned}/{self.points} points, {passed} of {count} checks passed"
        )
        return "\n".join(lines)

    def details(self, width: int = 100) -> str:
        """The full message of every check that did not pass."""
        blocks = []
        for check in self.checks:
            if check.passed:
                continue
            body = "\n".join(
                textwrap.fill(line, width, initial_indent="  ", subsequent_indent="  ")
                for line in _full_message(check).splitlines()
                if line.strip()
            )
            blocks.append(f"{_label(check)} ({check.outcome}):\n{body}")
        return "\n\n".join(blocks)


def _label(check: CheckResult) -> str:
    hidden = " (hidden)" if check.hidden else ""
    return f"task{check.task} {check.name}{hidden}"


def _full_message(check: CheckResult) -> str:
    if check.exception and check.exception not in ("CheckFailed", "AssertionError"):
        return f"{check.exception}: {check.message}"
    return check.message or "(no message)"


def _shorten(text: str, width: int) -> str:
    return text if len(text) <= width else text[: width - 1] + "…"
