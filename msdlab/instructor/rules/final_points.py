"""Each row's final points: the checks' points, manual changes, and the late penalty.

    total = points (the checks') − late_penalty + adjustment

A row without any task points (the grader failed on it: its task cells are empty, not 0)
gets no points, no penalty and no total: nothing that reads as a grade.

Task changes (`adjustments`) come first; the late penalty is taken from the points after
them; then the changes to the total. ``adjustment`` is whatever the manual changes added
in all. Every grading run settles every row of the grades file again, so a row kept from
an earlier run gets the changes made since. Without ``--due`` a run leaves earlier rows'
penalties as they were and refuses to grade again a row charged against a due date
(`forgotten_due`). ``msdlab export`` settles with the same `settle`.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from datetime import datetime
from fractions import Fraction
from pathlib import Path

from ...course import TASKS
from ..intake import HandIn, file_stem
from ..intake.times import in_zone
from ..outputs import output_files
from .adjustments import Change
from .late import LatePolicy, format_points
from .problems import Problem

COLUMNS = ["points", "due", "handed_in", "handed_in_from", "handed_in_control", "late",
           "late_penalty", "adjustment"]  # fmt: skip
"""The grades file's columns between ``task5`` and ``total`` (``handed_in_control``: who
controls the hand-in time's record, `intake.times`)."""
MARK = "<!-- msdlab: late work and manual changes -->"
END = "<!-- msdlab: end of late work and manual changes -->"
_SECTION = re.compile(re.escape(MARK) + ".*?" + re.escape(END) + "\n*", re.S)
_HEADLINE = re.compile(r"^(\*\*-?[\d.]+ of [\d.]+ points\*\*|[\d.]+/[\d.]+ points).*\n", re.M)
"""The feedback's first line of points: the student's ``**P of Q points**``, the
instructor's ``P/Q points``; the section goes right below it."""


@dataclass
class Terms:
    """The class's due date (None: no late penalties charged this run), its late policy,
    each student's own due date, hand-in times read this run, and the manual changes."""

    due: datetime | None = None
    policy: LatePolicy = field(default_factory=LatePolicy)
    own_due: dict[str, datetime] = field(default_factory=dict)
    handed_in: dict[str, HandIn] = field(default_factory=dict)
    changes: dict[str, list[Change]] = field(default_factory=dict)

    def due_of(self, identifier: str) -> datetime | None:
        return self.own_due.get(identifier, self.due)


def worth(maximum: Mapping[str, str]) -> dict[str, Fraction] | None:
    """What each task (``task1`` ...) and the ``total`` are worth, from the grades' row of
    maximum points (None if a run has not written it yet)."""
    columns = [*(f"task{task}" for task in TASKS), "total"]
    if not all(maximum.get(column) for column in columns):
        return None
    return {column: Fraction(maximum[column]) for column in columns}


def settle(rows: dict[str, dict[str, str]], terms: Terms) -> dict[str, list[str]]:
    """Write every row's final columns; return for each id the lines its feedback shows
    (none for a row with neither a due date nor a change)."""
    return {identifier: _settle_row(identifier, row, terms) for identifier, row in rows.items()}


def _settle_row(identifier: str, row: dict[str, str], terms: Terms) -> list[str]:
    if not any(row.get(f"task{t}") for t in TASKS):  # no points at all: the grader failed
        row.update({column: "" for column in ("points", "late", "late_penalty", "adjustment")})
        row["total"] = ""
        return []
    checks = {t: Fraction(row.get(f"task{t}") or 0) for t in TASKS}
    row["points"] = row.get("points") or format_points(sum(checks.values()))
    changes = terms.changes.get(identifier, [])
    lines = [f"- {change}" for change in changes]
    for change in (c for c in changes if c.task is not None):
        checks[change.task] = change.apply(checks[change.task])
    points = sum(checks.values())
    _stamp(row, terms.handed_in.get(identifier))
    due = terms.due_of(identifier)
    if due is not None:
        _charge(row, points, due, terms, identifier in terms.own_due)
    penalty = Fraction(row.get("late_penalty") or 0)
    if row.get("late"):
        lines.append(f"- {row['late']}")
    total = points - penalty
    for change in (c for c in changes if c.task is None):
        total = change.apply(total)
    row["adjustment"] = format_points(total - Fraction(row["points"]) + penalty) if changes else ""
    row["total"] = format_points(total)
    return lines


def forgotten_due(
    rows: Mapping[str, Mapping[str, str]], regraded: Iterable[str], terms: Terms, where: str
) -> list[Problem]:
    """A student graded again without a due date whose row was charged against one: the new
    row would drop the penalty silently (the rows of ``where``, the grades file)."""
    return [
        Problem(
            f"{where}, row {identifier!r}",
            f"was graded against the due date {rows[identifier]['due']}; grading it again "
            "without one would drop its late penalty",
            "give --due (and --late-policy, --extensions) as in that run",
        )
        for identifier in regraded
        if terms.due_of(identifier) is None and (rows.get(identifier) or {}).get("due")
    ]


def _stamp(row: dict[str, str], handed: HandIn | None) -> None:
    """The row's hand-in time and where it was read (kept as it was if not read this run)."""
    if handed is not None:
        row["handed_in"] = handed.time.isoformat(timespec="seconds") if handed.time else ""
        row["handed_in_from"] = handed.source
        row["handed_in_control"] = handed.control


def _charge(row: dict[str, str], points: Fraction, due: datetime, terms: Terms, own: bool) -> None:
    """The late penalty on ``points`` of a row due at ``due`` (``own``: an extension)."""
    row["due"] = due.isoformat(timespec="minutes")
    if not row.get("handed_in"):
        row["late"], row["late_penalty"] = "hand-in time unknown: no late penalty", ""
        return
    handed = datetime.fromisoformat(row["handed_in"])
    lateness = terms.policy.charge(points, handed - due)
    shown = _shown(in_zone(handed, due))
    when = f"due {_shown(due)}{' (your extension)' if own else ''}, handed in {shown}"
    row["late"] = f"{when} ({_evidence(row)}): {lateness.reason}"
    row["late_penalty"] = format_points(lateness.penalty) if lateness.penalty else ""


def _evidence(row: dict[str, str]) -> str:
    """Where the hand-in time was read, and whether the student could have set it."""
    source = row.get("handed_in_from") or "time"
    control = row.get("handed_in_control")
    return f"{source}, {CONTROL_SHOWN[control]}" if control in CONTROL_SHOWN else source


CONTROL_SHOWN = {"student": "set by the student's machine, not verified",
                 "unreadable": "unreadable"}  # fmt: skip


def _shown(moment: datetime) -> str:
    return moment.strftime("%Y-%m-%d %H:%M UTC%z").replace("UTC+0000", "UTC")


def feedback_section(row: dict[str, str], lines: list[str], possible: str) -> str:
    """The feedback's section on late work and manual changes ('' if there is none)."""
    if not lines:
        return ""
    return "\n".join([
        MARK, "", "## Late work and manual changes", "",
        f"The checks gave {row['points']} of {possible} points.", "", *lines, "",
        f"**Total: {row['total']} of {possible} points** (checks {row['points']}"
        f"{_term(' − late penalty ', row.get('late_penalty'))}"
        f"{_term(' + adjustment ', row.get('adjustment'))}).", "", END, "",
    ])  # fmt: skip


def _term(label: str, value: str | None) -> str:
    if not value or Fraction(value) == 0:
        return ""
    if label.startswith(" + ") and Fraction(value) < 0:
        return f" − adjustment {format_points(-Fraction(value))}"
    return f"{label}{value}"


def refresh_feedback(
    folder: Path,
    rows: dict[str, dict[str, str]],
    lines: dict[str, list[str]],
    possible: str,
    private: Mapping[str, list[str]] | None = None,
) -> None:
    """Put the section on late work and manual changes into each feedback file there is
    (the student's and the instructor's, which alone adds the ``private`` lines, e.g. the
    adjustments' notes), replacing the one an earlier run wrote."""
    for identifier, row in rows.items():
        shown = lines.get(identifier, [])
        for kind, extra in (("students", []), ("instructor", (private or {}).get(identifier, []))):
            section = feedback_section(row, [*shown, *extra], possible)
            path = output_files.not_a_link(Path(folder) / kind / f"{file_stem(identifier)}.md")
            if path.is_file():
                text = with_section(path.read_text(encoding="utf-8"), section)
                output_files.write_text(path, text, "feedback file")


def with_section(text: str, section: str) -> str:
    """The feedback ``text`` with ``section`` (none if '') below its first line of points
    (at its end if it has none), in place of the section it had."""
    text = _SECTION.sub("", text).rstrip("\n") + "\n"
    if not section:
        return text
    headline = _HEADLINE.search(text)
    if headline is None:
        return text.rstrip("\n") + "\n\n" + section
    return f"{text[: headline.end()]}\n{section}{text[headline.end() :].lstrip(chr(10))}"
