"""The class at a glance after grading: one offline HTML page and a section of summary.md.

The page (`write_html`, no network: its style inline, its pictures PNG data URIs) shows
the points per task (a histogram each and their numbers), each check's failure rate over
the students graded with it, the causes the failing checks named (the mistake a check
recognised in the result, or the "Usual cause: ..." of its message) and how many students
had each, a check × student map, the students whose hand-in time could not be verified
and those not graded. `summary_section` gives the same findings as Markdown.

It reads `ClassRow`s, one per row of the grades file (`rows_of`): a row's per-check results
come from its report in the gradebook (`render` passes every record's, with the messages
that name the causes), else from the grades file's per-check columns (a row taken in from
an older grades file with ``--detail``), else they are not known.
"""

from __future__ import annotations

import base64
import collections
import html
import io
import re
import statistics
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ...course import TASKS
from ...course.report import MISTAKE_SENTENCE, CheckResult
from ..intake.times import STUDENT, UNREADABLE
from ..judging.grading import Grade
from ..points.gradebook import Gradebook, check_column
from .html_page import write_page

if TYPE_CHECKING:
    from matplotlib.figure import Figure

TRUSTED_SOURCES = ("Gradescope's submission time",)
"""Hand-in times the student's own machine did not set (see `intake.times.NAMES`)."""
UNKNOWN_TIME, UNREADABLE_TIME = "hand-in time unknown", "hand-in time unreadable"
CAUSE = re.compile(
    rf"(?:Usual cause: |{re.escape(MISTAKE_SENTENCE.split('{}')[0])})([^\n]*?)\.?\s*(?:\n|$)"
)
"""A cause in a failing check's message: its usual cause, or the mistake it recognised."""
LISTED = 10
"""Students named per usual cause (the count covers all of them)."""
PASSED, FAILED, NOT_RUN = 0, 1, 2  # a cell of the check × student map


@dataclass(frozen=True)
class CheckOutcome:
    """One check's result for one student; ``cause`` the usual cause it named when failing."""

    task: int
    name: str
    passed: bool
    cause: str | None = None

    @property
    def column(self) -> str:
        return check_column(self.task, self.name)


@dataclass(frozen=True)
class ClassRow:
    """One student's row: points by task, total, check results (empty: not known), and why
    their hand-in time could not be verified (None: it could, or no due date needs it)."""

    id: str
    graded: bool
    points: dict[int, float]
    total: float
    checks: tuple[CheckOutcome, ...]
    unverified: str | None
    notes: str = ""


def rows_of(book: Gradebook, grades: Sequence[Grade]) -> list[ClassRow]:
    """Every row of ``book`` as a `ClassRow`, its checks from its report in ``grades`` where
    there is one, else from the book's per-check columns."""
    reports = {g.submission: g.report for g in grades if g.report is not None}
    rows = []
    for identifier in sorted(book.rows):
        row = book.rows[identifier]
        if identifier in reports:
            checks = tuple(
                CheckOutcome(c.task, c.name, c.passed, None if c.passed else cause_of(c))
                for c in reports[identifier].checks
            )
        else:
            checks = _from_columns(row, book)
        rows.append(
            ClassRow(
                identifier,
                bool(row.get("fingerprint")),
                {t: float(row.get(f"task{t}") or 0) for t in TASKS},
                float(row.get("total") or 0),
                checks,
                unverified(row),
                row.get("notes", ""),
            )
        )
    return rows


def _from_columns(row: dict[str, str], book: Gradebook) -> tuple[CheckOutcome, ...]:
    outcomes = []
    for column in (c for c in book.detail_columns if row.get(c)):
        task, name = column.split(" ", 1)
        passed = float(row[column]) >= float(book.maximum[column])
        outcomes.append(CheckOutcome(int(task.removeprefix("task")), name, passed))
    return tuple(outcomes)


def cause_of(check: CheckResult) -> str | None:
    """The cause a failing check named: the mistake it recognised in the result, else the
    usual cause its message names (a message kept without the mistake's field says both the
    same way), else None."""
    if check.mistake:
        return check.mistake
    found = CAUSE.search(check.message or "")
    return found.group(1).strip() if found else None


def unverified(row: dict[str, str]) -> str | None:
    """Why a row's hand-in time could not be verified: not known (or not readable), or, where
    a due date applies, kept by a clock the student controls (``handed_in_control``; a row
    from before that column: any source but `TRUSTED_SOURCES`)."""
    control, notes = row.get("handed_in_control", ""), row.get("notes", "")
    unknown = row.get("late", "").startswith(UNKNOWN_TIME) or UNKNOWN_TIME in notes
    if control == UNREADABLE or unknown or UNREADABLE_TIME in notes:
        return "hand-in time unknown"
    source = row.get("handed_in_from", "")
    set_by_student = control == STUDENT if control else source not in TRUSTED_SOURCES
    if row.get("due") and source and set_by_student:
        return f"hand-in time from the {source}, which the student's machine set"
    return None


@dataclass(frozen=True)
class CheckRate:
    """How many of the students graded with a check failed it."""

    column: str
    failed: int
    graded: int

    @property
    def rate(self) -> float:
        return self.failed / self.graded if self.graded else 0.0


def failure_rates(rows: Sequence[ClassRow]) -> list[CheckRate]:
    """Each check's failure rate over the graded rows that have its result, worst first."""
    failed, having = collections.Counter(), collections.Counter()
    for row in (r for r in rows if r.graded):
        for check in row.checks:
            having[check.column] += 1
            failed[check.column] += not check.passed
    rates = [CheckRate(column, failed[column], having[column]) for column in having]
    return sorted(rates, key=lambda r: (-r.rate, -r.failed, r.column))


@dataclass(frozen=True)
class Misconception:
    """A usual cause the checks named (its headline), who had it, and one full wording."""

    cause: str
    students: list[str]
    example: str


def usual_causes(rows: Sequence[ClassRow]) -> list[Misconception]:
    """Each usual cause the failing checks named, by its `headline`, and the students who
    had it, most first."""
    students, examples = collections.defaultdict(set), {}
    for row in (r for r in rows if r.graded):
        for check in (c for c in row.checks if c.cause):
            students[headline(check.cause)].add(row.id)
            examples.setdefault(headline(check.cause), check.cause)
    found = [Misconception(c, sorted(s), examples[c]) for c, s in students.items()]
    return sorted(found, key=lambda m: (-len(m.students), m.cause))


def headline(cause: str) -> str:
    """A cause without the details one check adds (the student's own numbers): the words
    before a colon, without a closing "(your ...)" ("the stiffness argument is ignored
    (your STIFFNESS = 0.5 used instead of k = 2)" -> "the stiffness argument is ignored")."""
    return re.sub(r" \(your [^()]*\)$", "", cause.split(": ", 1)[0])


def unverified_groups(rows: Sequence[ClassRow]) -> list[tuple[str, list[str]]]:
    """The students whose hand-in time could not be verified, by reason, most first."""
    students = collections.defaultdict(list)
    for row in (r for r in rows if r.unverified):
        students[row.unverified].append(row.id)
    return sorted(students.items(), key=lambda item: (-len(item[1]), item[0]))


def task_statistics(
    rows: Sequence[ClassRow], maximum: dict[str, str]
) -> list[tuple[str, list[float]]]:
    """The points of every graded row per task the checks grade (worth more than 0 in
    ``maximum``, the gradebook's row of what each column is worth), then the totals."""
    graded = [r for r in rows if r.graded]
    tasks = [t for t in TASKS if float(maximum.get(f"task{t}") or 0) > 0]
    columns = [(f"task{t}", [r.points[t] for r in graded]) for t in tasks]
    return [*columns, ("total", [r.total for r in graded])]


def summary_section(rows: Sequence[ClassRow], page: str) -> str:
    """The class report's findings as a Markdown section of summary.md."""
    lines = ["", "## The class at a glance", "", f"Pictures and every check: `{page}`.", ""]
    causes = usual_causes(rows)
    if causes:
        lines += ["Usual causes the failing checks named:", ""]
        lines += [f"- {m.cause}: {len(m.students)} ({_named(m.students)})" for m in causes]
        lines.append("")
    doubtful = unverified_groups(rows)
    count = sum(len(ids) for _, ids in doubtful)
    lines.append(f"Hand-in time not verified: {count}" + (":" if doubtful else "."))
    lines += [f"- {reason}: {len(ids)} ({_named(ids)})" for reason, ids in doubtful]
    missing = [r for r in rows if not r.graded]
    if missing:
        lines += ["", f"Not graded: {len(missing)}:"]
        lines += [f"- {r.id}: {r.notes or 'no reason recorded'}" for r in missing]
    return "\n".join(lines) + "\n"


def _named(ids: list[str]) -> str:
    more = f", and {len(ids) - LISTED} more" if len(ids) > LISTED else ""
    return ", ".join(ids[:LISTED]) + more


def beside(grades_file: Path) -> Path:
    """Where the class report of a grades file goes: grades.csv -> grades.class.html."""
    return grades_file.with_name(f"{grades_file.stem}.class.html")


def write_html(rows: Sequence[ClassRow], maximum: dict[str, str], path: Path) -> None:
    """The class report, one offline HTML file, to ``path``; ``maximum`` is the gradebook's
    row of the points each column is worth."""
    graded = [r for r in rows if r.graded]
    columns = task_statistics(rows, maximum)
    body = [
        "<h1>The class at a glance</h1>",
        f"<p>{len(graded)} of {len(rows)} students graded. It reports; it changes no points.</p>",
        "<h2>Points per task</h2>",
        _histograms_part(columns, maximum) if graded else "",
        "<h2>Checks failed most often</h2>",
        _rates_table(failure_rates(rows)),
        "<h2>Usual causes</h2>",
        _causes_table(usual_causes(rows)),
        "<h2>Checks × students</h2>",
        _heatmap_part(rows),
        "<h2>Hand-in time not verified</h2>",
        _list(
            [f"{why}: {len(ids)} ({', '.join(ids)})" for why, ids in unverified_groups(rows)],
            "none",
        ),
        "<h2>Not graded</h2>",
        _list([f"{r.id}: {r.notes or 'no reason recorded'}" for r in rows if not r.graded], "none"),
    ]
    write_page(path, "The class at a glance", STYLE, body)


STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; max-width: 75em; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
td.number { text-align: right; font-variant-numeric: tabular-nums; }
img { max-width: 100%; height: auto; }
.bar { display: inline-block; height: 0.8em; background: #b0413e; }
details { margin: 0.5em 0 1em; }
summary { cursor: pointer; }
"""
MAP_COLOURS = {PASSED: "#56b4e9", FAILED: "#d55e00", NOT_RUN: "#eeeeee"}
"""The check × student map's colours (Okabe and Ito's, told apart with any colour vision);
a failed cell is marked × too, one not run with a dash."""
MAP_WORDS = {PASSED: "passed", FAILED: "✗ failed", NOT_RUN: "not run"}
MAP_LEGEND = "blue passed, orange × failed, light grey – not run"


def _histograms_part(columns: list[tuple[str, list[float]]], maximum: dict[str, str]) -> str:
    """The histograms, their statistics, and the counts they draw as a table."""
    text = (
        f"Histograms of the points of the {len(columns[0][1])} students graded, one per "
        "task and one of the totals; the tables below give their numbers"
    )
    counts = "".join(
        f"<tr><th scope='row'>{html.escape(name)}</th><td>{_counts(points)}</td></tr>"
        for name, points in columns
    )
    return (
        _picture(histograms(columns, maximum), text)
        + _statistics_table(columns, maximum)
        + "<details><summary>How many students had each number of points</summary><table>"
        + "<tr><th scope='col'>column</th><th scope='col'>points: students</th></tr>"
        + f"{counts}</table></details>"
    )


def _counts(points: list[float]) -> str:
    """``points`` as "0: 1, 3: 4" (points: how many students had them), lowest first."""
    tally = sorted(collections.Counter(points).items())
    return ", ".join(f"{value:g}: {count}" for value, count in tally)


def _statistics_table(columns: list[tuple[str, list[float]]], maximum: dict[str, str]) -> str:
    names = ("column", "worth", "mean", "median", "min", "max")
    head = "<tr>" + "".join(f"<th scope='col'>{name}</th>" for name in names) + "</tr>"
    rows = [
        f"<tr><th>{name}</th>"
        + "".join(
            f'<td class="number">{value}</td>'
            for value in (
                maximum.get(name, ""),
                f"{statistics.mean(points):.1f}",
                f"{statistics.median(points):g}",
                f"{min(points):g}",
                f"{max(points):g}",
            )
        )
        + "</tr>"
        for name, points in columns
    ]
    return f"<table>{head}{''.join(rows)}</table>"


def _rates_table(rates: list[CheckRate]) -> str:
    if not rates:
        return "<p>No check results are known (grade with --detail to keep them).</p>"
    passed = sum(not r.failed for r in rates)
    rates = [r for r in rates if r.failed]
    rest = f"<p>{passed} checks passed by every student graded with them.</p>" if passed else ""
    head = "<tr><th>check</th><th>failed by</th><th>of</th><th>rate</th></tr>"
    rows = [
        f"<tr><td>{html.escape(r.column)}</td><td class='number'>{r.failed}</td>"
        f"<td class='number'>{r.graded}</td><td><span class='bar' style='width: "
        f"{r.rate * 8:.2f}em'></span> {r.rate:.0%}</td></tr>"
        for r in rates
    ]
    return (f"<table>{head}{''.join(rows)}</table>" if rows else "") + rest


def _causes_table(causes: list[Misconception]) -> str:
    if not causes:
        return "<p>No failing check named a usual cause.</p>"
    head = "<tr><th>usual cause</th><th>students</th><th>who</th><th>as a check put it</th></tr>"
    rows = [
        f"<tr><td>{html.escape(m.cause)}</td><td class='number'>{len(m.students)}</td>"
        f"<td>{html.escape(_named(m.students))}</td><td>{html.escape(m.example)}</td></tr>"
        for m in causes
    ]
    return f"<table>{head}{''.join(rows)}</table>"


def _list(lines: list[str], empty: str) -> str:
    if not lines:
        return f"<p>{empty}</p>"
    return "<ul>" + "".join(f"<li>{html.escape(line)}</li>" for line in lines) + "</ul>"


def _heatmap_part(rows: Sequence[ClassRow]) -> str:
    """The check × student map, and the same as a table (folded: it may be long)."""
    known = [r for r in rows if r.graded and r.checks]
    if not known:
        return "<p>No check results are known (grade with --detail to keep them).</p>"
    layout = check_map(known)
    columns, students, cells = layout
    failed = sum(row.count(FAILED) for row in cells)
    text = (
        f"Map of {len(columns)} checks (rows) by {len(students)} students (columns, lowest "
        f"total first): {failed} failed results; {MAP_LEGEND}. The table below gives each cell"
    )
    head = "".join(f"<th scope='col'>{html.escape(c)}</th>" for c in columns)
    body = "".join(
        f"<tr><th scope='row'>{html.escape(student.id)}</th>"
        + "".join(f"<td>{MAP_WORDS[row[j]]}</td>" for row in cells)
        + "</tr>"
        for j, student in enumerate(students)
    )
    return (
        _picture(_draw_map(layout), text)
        + "<details><summary>The map as a table: each student's result of each check"
        + f"</summary><table><tr><th scope='col'>student</th>{head}</tr>{body}</table></details>"
    )


def _picture(figure: Figure, text: str) -> str:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100)
    encoded = base64.b64encode(buffer.getvalue()).decode("ascii")
    return f'<p><img alt="{html.escape(text)}" src="data:image/png;base64,{encoded}"></p>'


def histograms(columns: list[tuple[str, list[float]]], maximum: dict[str, str]) -> Figure:
    """One histogram of points per task and one of the totals (matplotlib, no display)."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(12, 6), layout="constrained")
    axes = figure.subplots(2, (len(columns) + 1) // 2).ravel()
    for ax, (name, points) in zip(axes, columns):
        top = float(maximum.get(name) or max(points) or 1)
        width = max(1.0, top / 20)  # at most 20 bars, each at least one point wide
        edges = [i * width - width / 2 for i in range(int(top / width) + 2)]
        ax.hist(points, bins=edges, color="#4a7fb5", edgecolor="white")
        ax.set(title=f"{name} (worth {top:g})", xlabel="points", ylabel="students")
        ax.set_xlim(-width, top + width)
        ax.xaxis.get_major_locator().set_params(integer=True)
        ax.yaxis.get_major_locator().set_params(integer=True)
    for ax in axes[len(columns) :]:
        ax.set_visible(False)
    return figure


MapLayout = tuple[list[str], list[ClassRow], list[list[int]]]
"""The check × student map: its checks, its students, and cells[check][student]."""


def check_map(rows: Sequence[ClassRow]) -> MapLayout:
    """Checks (by task) × students (lowest total first): `PASSED`, `FAILED`, `NOT_RUN`."""
    seen = {c.column: c.task for r in rows for c in r.checks}  # in the reports' order
    columns = sorted(seen, key=seen.__getitem__)
    students = sorted(rows, key=lambda r: (r.total, r.id))
    where = {column: i for i, column in enumerate(columns)}
    cells = [[NOT_RUN] * len(students) for _ in columns]
    for j, row in enumerate(students):
        for check in row.checks:
            cells[where[check.column]][j] = PASSED if check.passed else FAILED
    return columns, students, cells


def heatmap(rows: Sequence[ClassRow]) -> Figure:
    """Checks (rows, by task) × students (columns, lowest total first): passed, failed
    (marked ×), not run (marked –)."""
    return _draw_map(check_map(rows))


def _draw_map(layout: MapLayout) -> Figure:
    from matplotlib.colors import ListedColormap
    from matplotlib.figure import Figure

    columns, students, cells = layout
    width = min(6 + 0.22 * len(students), 14)  # inches: the check names, then the students
    figure = Figure(figsize=(width, 1.5 + 0.18 * len(columns)), layout="constrained")
    ax = figure.subplots()
    colours = ListedColormap([MAP_COLOURS[kind] for kind in (PASSED, FAILED, NOT_RUN)])
    ax.imshow(cells, cmap=colours, vmin=0, vmax=2, aspect="auto", interpolation="nearest")
    for kind, marker in ((FAILED, "x"), (NOT_RUN, "_")):
        where = [
            (j, i) for i, row in enumerate(cells) for j, cell in enumerate(row) if cell == kind
        ]
        if where:
            ax.scatter(*zip(*where), marker=marker, s=18, c="black", linewidths=0.8)
    ax.set_yticks(range(len(columns)), columns, fontsize=7, parse_math=False)
    if len(students) <= 60:
        ax.set_xticks(
            range(len(students)),
            [r.id for r in students],
            rotation=90,
            fontsize=7,
            parse_math=False,
        )
    else:
        ax.set_xticks([])
    ax.set_xlabel(f"{len(students)} students, lowest total on the left", fontsize=9)
    ax.set_title(MAP_LEGEND, fontsize=9)
    return figure
