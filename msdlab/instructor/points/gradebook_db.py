"""The class's gradebook: a SQLite database beside the grades file, the record of every run.

``msdlab grade --out grades.csv`` keeps its record in ``grades.db`` (`beside`). Each
submission's result is committed, in one transaction, as soon as it is graded; the
grades file, the feedback files, the summary and the exports are views rendered from
this database (`msdlab.instructor.outputs.render`), so they can be rebuilt at any time and always
cover the whole class. Two runs may write into one database at once (WAL journal, a busy
timeout): each commit is whole, and neither loses the other's rows.

Tables (schema `SCHEMA_VERSION`):

- ``submissions``: one row per id: ``source`` (the folder or zip handed in, escaped as
  `intake.escaped` writes it), ``status`` (`GRADED`, `NOT_GRADED`: the submission could
  not be graded for a reason of its own, `ABSENT`: nothing handed in, `GRADER_FAILED`:
  the grader's failure, never the student's), ``fingerprint`` (of the checks and the task
  files, set only when graded), ``handed_in`` and ``handed_in_from`` (the hand-in time,
  ISO 8601, and where it was read), ``notes`` (a JSON list), ``seconds`` (grading time),
  ``attempts`` (how often the grader tried), ``run`` and ``graded_at`` (UTC, ISO 8601),
  ``hint`` (for the instructor only, never a student: whose own numbers it holds).
- ``checks``: one row per check of a graded submission, in the report's order
  (``position``): the fields of `CheckResult` (``task``, ``name``, ``points``,
  ``hidden``, ``outcome``, ``exception``, ``message``, ``duration``, ``nodeid``,
  ``mistake``, ...).
- ``tasks``: per submission and task the points ``earned`` of ``possible`` (from its
  checks, or imported from an older grades file, which has no checks).
- ``final``: the term's rules applied to each row (`final_points.COLUMNS`: ``points``,
  ``due``, ``late``, ``late_penalty``, ``adjustment``, ...) and its ``total``, with
  ``explained`` (a JSON list of the lines the feedback shows).
- ``changes``: the manual changes applied (``line`` in the adjustments file, ``task``
  or NULL for the total, ``change`` as written, ``reason``).
- ``runs``: each grading run (``command``, ``started``, ``finished``, ``outcome``:
  running, finished or interrupted), ``meta``: the schema version and settings.

Reading (for reports): `read_class` gives every submission as a `Record` with its task
points, final total and check results; `connect` opens the database for SQL of one's own.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import socket
import sqlite3
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from ...course import TASKS
from ...course.report import CheckReport, CheckResult
from ..outputs import output_files
from ..rules.final_points import COLUMNS as FINAL_COLUMNS

SCHEMA_VERSION = 1
GRADED, NOT_GRADED, ABSENT, GRADER_FAILED = "graded", "not graded", "absent", "grader failed"
STATUSES = (GRADED, NOT_GRADED, ABSENT, GRADER_FAILED)
BUSY_SECONDS = 120.0
"""How long a write waits for another run's transaction to end."""
CHECK_FIELDS = tuple(field.name for field in dataclasses.fields(CheckResult))
"""The ``checks`` table's columns after ``submission`` and ``position``: a field added to
`CheckResult` later is added to an older gradebook's table when it is opened."""
JOURNALS = ("-wal", "-shm", "-journal")
"""The files SQLite keeps beside the gradebook."""
SETTLED = [column for column in FINAL_COLUMNS if column not in ("handed_in", "handed_in_from")]

_SCHEMA = f"""
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS runs (
    run INTEGER PRIMARY KEY AUTOINCREMENT, command TEXT NOT NULL, host TEXT, pid INTEGER,
    started TEXT NOT NULL, finished TEXT, outcome TEXT NOT NULL DEFAULT 'running');
CREATE TABLE IF NOT EXISTS submissions (
    id TEXT PRIMARY KEY, source TEXT NOT NULL,
    status TEXT NOT NULL CHECK (status IN ({", ".join(f"'{s}'" for s in STATUSES)})),
    fingerprint TEXT, handed_in TEXT, handed_in_from TEXT,
    notes TEXT NOT NULL DEFAULT '[]', seconds REAL, attempts INTEGER NOT NULL DEFAULT 1,
    run INTEGER REFERENCES runs (run), graded_at TEXT NOT NULL, hint TEXT);
CREATE TABLE IF NOT EXISTS checks (
    submission TEXT NOT NULL REFERENCES submissions (id) ON DELETE CASCADE,
    position INTEGER NOT NULL, {", ".join(CHECK_FIELDS)}, PRIMARY KEY (submission, position));
CREATE TABLE IF NOT EXISTS tasks (
    submission TEXT NOT NULL REFERENCES submissions (id) ON DELETE CASCADE,
    task INTEGER NOT NULL, earned TEXT NOT NULL, possible TEXT NOT NULL,
    PRIMARY KEY (submission, task));
CREATE TABLE IF NOT EXISTS final (
    submission TEXT PRIMARY KEY REFERENCES submissions (id) ON DELETE CASCADE,
    {", ".join(f"{column} TEXT NOT NULL DEFAULT ''" for column in SETTLED)},
    total TEXT NOT NULL DEFAULT '', explained TEXT NOT NULL DEFAULT '[]');
CREATE TABLE IF NOT EXISTS changes (
    submission TEXT NOT NULL, line INTEGER NOT NULL, task INTEGER, change TEXT NOT NULL,
    reason TEXT NOT NULL);
"""


@dataclass
class Record:
    """One submission as the gradebook holds it (see the module docstring's tables)."""

    id: str
    source: str
    status: str
    fingerprint: str | None
    handed_in: str | None
    handed_in_from: str | None
    notes: list[str]
    seconds: float | None
    attempts: int
    graded_at: str
    hint: str | None = None
    tasks: dict[int, tuple[str, str]] = field(default_factory=dict)
    """task -> (points earned, points possible), as decimal text."""
    final: dict[str, str] = field(default_factory=dict)
    """The term's rules applied: `final_points.COLUMNS` and ``total`` (empty before any)."""
    explained: list[str] = field(default_factory=list)
    checks: list[CheckResult] = field(default_factory=list)

    @property
    def report(self) -> CheckReport | None:
        """The checks' report, or None (not graded, or imported without checks)."""
        return CheckReport(self.source, list(self.checks)) if self.checks else None


def beside(grades: Path) -> Path:
    """The gradebook of the grades file ``grades`` (grades.csv -> grades.db)."""
    grades = Path(grades)
    if grades.suffix == ".db":
        raise ValueError(f"--out {grades}: give the grades file (grades.csv), not the database")
    return grades.with_suffix(".db")


def connect(path: Path) -> sqlite3.Connection:
    """The gradebook at ``path``, created if new, ready for another run beside this one
    (WAL journal, a busy timeout of `BUSY_SECONDS`). Commit with ``with connection:``."""
    path = Path(path)
    _not_linked(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    connection = sqlite3.connect(path, timeout=BUSY_SECONDS, isolation_level=None)
    try:
        connection.execute("PRAGMA journal_mode=WAL")
        connection.execute("PRAGMA foreign_keys=ON")
        with transaction(connection):
            for statement in _SCHEMA.split(";")[:-1]:
                connection.execute(statement)
            _check_version(connection, path)
            _add_check_fields(connection)
    except sqlite3.DatabaseError as error:
        connection.close()
        raise ValueError(
            f"{path} is not a gradebook msdlab can read ({error}); give another --out"
        ) from None
    return connection


def _not_linked(path: Path) -> None:
    """Refuse a gradebook (or its journal files, its folder) that is a symbolic link: the
    class's rows would be written wherever it points."""
    for place in (path, *(path.with_name(path.name + end) for end in JOURNALS)):
        output_files.not_a_link(place, "gradebook")


@contextlib.contextmanager
def transaction(connection: sqlite3.Connection) -> Iterator[sqlite3.Connection]:
    """A write transaction that holds the database's write lock from its start
    (``BEGIN IMMEDIATE``): what it reads, no other run changes before it commits."""
    connection.execute("BEGIN IMMEDIATE")
    try:
        yield connection
    except BaseException:
        connection.execute("ROLLBACK")
        raise
    connection.execute("COMMIT")


def _add_check_fields(connection: sqlite3.Connection) -> None:
    """Add to the ``checks`` table the `CheckResult` fields it lacks (made by an older msdlab)."""
    present = {row[1] for row in connection.execute("PRAGMA table_info(checks)")}
    for name in (name for name in CHECK_FIELDS if name not in present):
        connection.execute(f"ALTER TABLE checks ADD COLUMN {name}")


def _check_version(connection: sqlite3.Connection, path: Path) -> None:
    row = connection.execute("SELECT value FROM meta WHERE key = 'schema'").fetchone()
    if row is None:
        connection.execute("INSERT INTO meta VALUES ('schema', ?)", (str(SCHEMA_VERSION),))
    elif int(row[0]) != SCHEMA_VERSION:
        raise sqlite3.DatabaseError(
            f"schema {row[0]}, this msdlab reads schema {SCHEMA_VERSION}; update msdlab"
        )


def now() -> str:
    """The time now, UTC, ISO 8601 to the second."""
    return datetime.now(UTC).isoformat(timespec="seconds")


def start_run(connection: sqlite3.Connection, command: Sequence[str]) -> int:
    """Record that a grading run started with ``command``; its run number."""
    with transaction(connection):
        cursor = connection.execute(
            "INSERT INTO runs (command, host, pid, started) VALUES (?, ?, ?, ?)",
            (json.dumps(list(command)), socket.gethostname(), os.getpid(), now()),
        )
    return int(cursor.lastrowid)


def end_run(connection: sqlite3.Connection, run: int, outcome: str) -> None:
    """Record how run ``run`` ended (finished, interrupted)."""
    with transaction(connection):
        connection.execute(
            "UPDATE runs SET finished = ?, outcome = ? WHERE run = ?", (now(), outcome, run)
        )


@dataclass
class Result:
    """What one grading of a submission gives the gradebook."""

    id: str
    source: str
    status: str
    notes: list[str]
    report: CheckReport | None = None
    fingerprint: str | None = None
    handed_in: str | None = None
    handed_in_from: str | None = None
    seconds: float | None = None
    attempts: int = 1
    hint: str | None = None


def record(connection: sqlite3.Connection, result: Result, run: int | None) -> None:
    """Commit ``result`` (replacing the submission's earlier row, checks and points)."""
    if result.status not in STATUSES:
        raise ValueError(f"status {result.status!r} is not one of {STATUSES}")
    with transaction(connection):
        connection.execute("DELETE FROM checks WHERE submission = ?", (result.id,))
        connection.execute("DELETE FROM tasks WHERE submission = ?", (result.id,))
        connection.execute(
            "INSERT OR REPLACE INTO submissions (id, source, status, fingerprint, handed_in, "
            "handed_in_from, notes, seconds, attempts, run, graded_at, hint) "
            "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (result.id, result.source, result.status,
             result.fingerprint if result.status == GRADED else None,
             result.handed_in, result.handed_in_from, json.dumps(result.notes),
             result.seconds, result.attempts, run, now(), result.hint),
        )  # fmt: skip
        if result.report is not None:
            _record_checks(connection, result.id, result.report)


def _record_checks(connection: sqlite3.Connection, identifier: str, report: CheckReport) -> None:
    connection.executemany(
        f"INSERT INTO checks (submission, position, {', '.join(CHECK_FIELDS)}) "
        f"VALUES (?, ?, {', '.join('?' for _ in CHECK_FIELDS)})",
        [
            (identifier, position, *(getattr(check, name) for name in CHECK_FIELDS))
            for position, check in enumerate(report.checks)
        ],
    )
    connection.executemany(
        "INSERT INTO tasks VALUES (?, ?, ?, ?)",
        [
            (identifier, task, str(sum(c.earned for c in report.checks if c.task == task)),
             str(sum(c.points for c in report.checks if c.task == task)))
            for task in TASKS
        ],
    )  # fmt: skip


def record_imported(
    connection: sqlite3.Connection, row: dict[str, str], maximum: dict[str, str]
) -> None:
    """Take in a row of an older grades file (no checks: its task points and columns; its
    status where it has one, so a row the grader failed on keeps having no points)."""
    graded = bool(row.get("fingerprint"))
    status = row.get("status") if row.get("status") in STATUSES else None
    status = status or (GRADED if graded else NOT_GRADED)
    nothing = "" if status == GRADER_FAILED else "0"
    notes = [note for note in (row.get("notes") or "").split("; ") if note]
    connection.execute(
        "INSERT OR REPLACE INTO submissions (id, source, status, fingerprint, handed_in, "
        "handed_in_from, notes, graded_at) VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
        (row["id"], row.get("source", ""), status,
         row.get("fingerprint") or None, row.get("handed_in") or None,
         row.get("handed_in_from") or None, json.dumps(notes), now()),
    )  # fmt: skip
    connection.executemany(
        "INSERT OR REPLACE INTO tasks VALUES (?, ?, ?, ?)",
        [(row["id"], t, row.get(f"task{t}") or nothing, maximum.get(f"task{t}") or "0")
         for t in TASKS],
    )  # fmt: skip
    settled = {column: row.get(column) or "" for column in SETTLED}
    store_final(connection, row["id"], settled | {"total": row.get("total") or ""}, [])


def store_final(
    connection: sqlite3.Connection, identifier: str, row: dict[str, str], explained: list[str]
) -> None:
    """The term's rules applied to ``identifier``'s row (inside the caller's transaction)."""
    columns = [*SETTLED, "total"]
    connection.execute(
        f"INSERT OR REPLACE INTO final (submission, {', '.join(columns)}, explained) "
        f"VALUES (?, {', '.join('?' for _ in columns)}, ?)",
        (identifier, *(row.get(column) or "" for column in columns), json.dumps(explained)),
    )


def store_changes(connection: sqlite3.Connection, changes: dict[str, list]) -> None:
    """The manual changes applied (`adjustments.Change` by id), replacing the earlier ones."""
    connection.execute("DELETE FROM changes")
    connection.executemany(
        "INSERT INTO changes VALUES (?, ?, ?, ?, ?)",
        [
            (identifier, line, change.task, str(change), change.reason)
            for identifier, listed in changes.items()
            for line, change in enumerate(listed, start=1)
        ],
    )


def statuses(connection: sqlite3.Connection) -> dict[str, tuple[str, str | None]]:
    """Each id's status and fingerprint."""
    rows = connection.execute("SELECT id, status, fingerprint FROM submissions")
    return {identifier: (status, print_) for identifier, status, print_ in rows}


def read_records(connection: sqlite3.Connection) -> list[Record]:
    """Every submission of the gradebook, sorted by id, with its points and checks."""
    query = (
        "SELECT id, source, status, fingerprint, handed_in, handed_in_from, notes, seconds, "
        "attempts, graded_at, hint FROM submissions ORDER BY id"
    )
    records = {}
    for row in connection.execute(query):
        records[row[0]] = Record(*row[:6], json.loads(row[6]), *row[7:])
    for identifier, task, earned, possible in connection.execute("SELECT * FROM tasks"):
        records[identifier].tasks[task] = (earned, possible)
    columns = [*SETTLED, "total"]
    for row in connection.execute(f"SELECT submission, {', '.join(columns)}, explained FROM final"):
        records[row[0]].final = dict(zip(columns, row[1:-1], strict=True))
        records[row[0]].explained = json.loads(row[-1])
    query = f"SELECT submission, {', '.join(CHECK_FIELDS)} FROM checks"
    for identifier, *values in connection.execute(query + " ORDER BY submission, position"):
        check = CheckResult(**dict(zip(CHECK_FIELDS, values, strict=True)))
        check.hidden = bool(check.hidden)
        records[identifier].checks.append(check)
    return list(records.values())


def read_class(grades: Path) -> list[Record]:
    """Every submission in the gradebook of the grades file ``grades`` (see `Record`);
    a ValueError if there is none."""
    path = beside(grades)
    if not path.is_file():
        raise ValueError(f"no gradebook at {path}; run msdlab grade --out {grades} first")
    connection = connect(path)
    try:
        return read_records(connection)
    finally:
        connection.close()
