"""Taking in a class's submissions: whose each is, and a fresh folder of its plain files.

A submission is given as a folder laid out like ``assignments/``, a folder holding
``assignments/`` (a student who handed in the whole bundle), a zip file of either, a git
repository (a GitHub Classroom clone, or a folder inside one: ``class/alice/assignments``
of the clone ``class/alice``), or Gradescope's layout (a folder holding ``submission/``
and Gradescope's ``submission_metadata.json`` beside it). Each becomes an `Entry`: the
id, a fresh folder of the graded folder's plain files (`fresh`), the hand-in time with
who controls it (`times`), notes, or the problem why it is not graded.

Ids: from the roster (`from_roster`, or `from_paths` with ``known`` ids), else the path
below the submissions' common folder, without a trailing ``assignments`` or ``.zip``
(``class/alice/assignments`` → ``alice``). An id that is empty, has spaces around it, is
the gradebook's ``(max points)``, starts with a character a spreadsheet takes for a
formula, or differs from another only in case, is refused for that one submission
(`names.id_problem`): no row, a line on the console.

With a roster, the class is the roster's students and nothing is left unsaid: a student
who handed in nothing gets a row "nothing handed in" (`Entry.absent`), whether the run
names SUBMISSIONs or not; a hand-in whose id is not on the roster (a SUBMISSION, or a
hand-in lying beside the roster's ones that no roster line names: `beside_the_roster`)
gets a row "not graded" that says so (`NOT_ON_ROSTER`), and is not graded.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
import zipfile
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from datetime import datetime, timedelta, timezone, tzinfo
from pathlib import Path

from ...course import PROJECT_ROOT
from .archive import take_zip
from .folder import copy_files, graded_part, link_problem
from .fresh import BUNDLE_FOLDER, TASK_FILES, FreshFolder, Refused
from .names import id_problem, lookalike, readable
from .repository import Unreadable, is_repository, take_commit, unreadable_repository
from .roster import Student
from .roster import read as read_roster
from .times import (
    METADATA,
    HandIn,
    flag,
    gradescope_time,
    modification_time,
    under_policy,
    unreadable,
)

GRADESCOPE_FILES = "submission"
NOTHING_HANDED_IN = "nothing handed in"
"""What the row of a roster student who handed in nothing says (0 points)."""
NOT_ON_ROSTER = "which is not on the roster"
"""What the row of a hand-in whose id is no roster student's says (not graded)."""


@dataclass
class Entry:
    """One submission: its id, what was handed in (``source``), the fresh folder of its
    plain files that is graded, its hand-in time, and notes or a problem.

    ``problem`` is set when there is nothing to grade; such a submission gets a row with
    the problem and makes the run's exit status 1, unless the student is ``absent`` (the
    roster names them, nothing is at their path)."""

    id: str
    source: Path
    folder: Path
    notes: list[str] = field(default_factory=list)
    problem: str | None = None
    handed_in: HandIn | None = None
    absent: bool = False
    """True for a roster's student who handed in nothing (a row of 0 points)."""


@dataclass(frozen=True)
class Rules:
    """How hand-in times are read (`times.SOURCES`) and taken: the zone of a zip's
    wall-clock times, each student's due date, how long after it a commit still counts,
    what an unverified time gets (`times.UNVERIFIED_POLICIES`), and when this run took
    the submissions in."""

    source: str = "auto"
    zone: tzinfo | None = None
    due_of: Callable[[str], datetime | None] = lambda identifier: None
    cutoff: timedelta | None = None
    unverified: str = "flag"
    collected: datetime = field(default_factory=lambda: datetime.now(timezone.utc))


def task_files(folder: Path) -> list[str]:
    """The task files ``task1.py`` ... present in ``folder``."""
    return [name for name in TASK_FILES if (folder / name).is_file()]


class Intake(contextlib.AbstractContextManager):
    """The entries of one run; their fresh folders live until `close`."""

    def __init__(self, rules: Rules | None = None) -> None:
        self.rules = rules or Rules()
        self.entries: list[Entry] = []
        self.refused: list[str] = []
        """One line per submission refused for its id (it gets no row)."""
        self._scratch = Path(tempfile.mkdtemp(prefix="msdlab-intake-"))

    def close(self) -> None:
        shutil.rmtree(self._scratch, ignore_errors=True)

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def add(self, identifier: str, source: Path, given_in: Path | None = None,
            known: set[str] | None = None) -> Entry | None:  # fmt: skip
        """Take in the submission at ``source`` under ``identifier``; a link leading out of
        ``given_in`` (default: its parent) is not followed. An id that is not acceptable
        refuses the submission: no entry, a line in `refused`; one not in ``known`` (when
        given) is an entry that says so and is not taken (`unlisted`)."""
        source = Path(os.path.abspath(source))
        problem = self._id_problem(readable(identifier))
        if problem is not None:
            self.refused.append(f"not graded: {readable(str(source))}: {problem}")
            return None
        entry = Entry(readable(identifier), source, source)
        self.entries.append(entry)
        if known is not None and entry.id not in known:
            entry.problem = unlisted(entry.id, source)
            return entry
        try:
            entry.problem = link_problem(source, given_in or source.parent)
            if entry.problem is None:
                fresh = FreshFolder(self._scratch / str(len(self.entries)))
                entry.handed_in = self._take(entry, fresh, given_in or source.parent)
                entry.folder = fresh.path
                entry.notes += fresh.notes
                self._mark(entry)
        except Refused as refused:
            entry.problem = str(refused)
        except Exception as error:  # whatever one hand-in raises stops its row only
            entry.problem = unreadable_hand_in(source, error)
        return entry

    def add_absent(self, identifier: str, expected: Path | None) -> Entry | None:
        """Add a roster's student who handed in nothing (nothing at ``expected``, the row's
        source, or no path given): their row says "nothing handed in" and names no folder
        (the student reads it); an id that is not acceptable is refused as in `add`."""
        problem = self._id_problem(readable(identifier))
        if problem is not None:
            self.refused.append(f"not graded: {readable(identifier)!r}: {problem}")
            return None
        entry = Entry(readable(identifier), expected or Path(), expected or Path(),
                      problem=NOTHING_HANDED_IN, absent=True)  # fmt: skip
        self.entries.append(entry)
        return entry

    def add_gradescope(self, root: Path) -> Entry:
        """Take in Gradescope's upload at ``root`` (``/autograder``): the student's files in
        ``root/submission``, Gradescope's ``submission_metadata.json`` beside them."""
        entry = Entry("submission", Path(os.path.abspath(root)) / GRADESCOPE_FILES, root)
        self.entries.append(entry)
        fresh = FreshFolder(self._scratch / str(len(self.entries)))
        try:
            entry.handed_in = self._from_gradescope(entry.source.parent, fresh)
            entry.folder = fresh.path
            entry.notes += fresh.notes
            self._mark(entry)
        except Exception as error:  # said in the row, as for any other hand-in
            entry.problem = unreadable_hand_in(entry.source, error)
        return entry

    def _from_gradescope(self, root: Path, fresh: FreshFolder) -> HandIn:
        files = root / GRADESCOPE_FILES
        copy_files(files / graded_part(files), fresh)
        if (root / METADATA).is_file():
            return gradescope_time(root / METADATA)
        return unreadable("gradescope", f"no {METADATA} beside the submission")

    def _id_problem(self, identifier: str) -> str | None:
        """Why ``identifier`` is not taken (see the module), or None."""
        problem = id_problem(identifier)
        twin = next((e.id for e in self.entries if lookalike(e.id) == lookalike(identifier)), None)
        if problem is None and twin is not None:
            same = "is" if twin == identifier else "looks like"
            problem = f"the id {identifier!r} {same} {twin!r}, a submission taken in before it"
        if problem is None:
            return None
        return f"{problem}; give each student's submission under their roster id (--roster)"

    def _take(self, entry: Entry, fresh: FreshFolder, given_in: Path) -> HandIn:
        """Write ``entry``'s graded files into ``fresh``; return its hand-in time as read."""
        rules, source = self.rules, entry.source
        if source.is_file():
            if not zipfile.is_zipfile(source):
                raise Refused(f"not graded: {readable(source.name)} is not a folder or zip file")
            handed = take_zip(source, fresh, rules.zone)
            return handed if rules.source in ("auto", "zip") else _not_from(rules.source, "a zip")
        if (source / GRADESCOPE_FILES).is_dir() and (source / METADATA).is_file():
            return self._from_gradescope(source, fresh)
        repository = _repository_of(source, given_in)
        if repository is not None and rules.source in ("auto", "git"):
            return self._from_repository(entry, repository, fresh)
        times = copy_files(source / graded_part(source), fresh)
        if rules.source in ("auto", "mtime"):
            return modification_time(times)
        return _not_from(rules.source, "a folder")

    def _from_repository(self, entry: Entry, repository: Path, fresh: FreshFolder) -> HandIn:
        """The commit's files and time; the folder's files where there is no commit to read."""
        inside = entry.source.relative_to(repository).as_posix()
        due = self.rules.due_of(entry.id)
        cutoff = due + self.rules.cutoff if due and self.rules.cutoff is not None else None
        try:
            return take_commit(repository, "" if inside == "." else f"{inside}/", fresh, cutoff)
        except Unreadable as error:
            fresh.clear()
            copy_files(entry.source / graded_part(entry.source), fresh)
            return unreadable_repository(f"{error}; the folder's files as they are were graded")

    def _mark(self, entry: Entry) -> None:
        """The entry's notes on its time: a planted metadata file, an unverified time (as
        the rules take it), a missing task file."""
        rules, handed = self.rules, entry.handed_in
        if (entry.folder / METADATA).exists():
            entry.notes.append(
                f"the {METADATA} among the student's files was ignored: a student can write "
                "it; Gradescope's own lies beside the submission"
            )
        due = rules.due_of(entry.id)
        if handed is not None and due is not None:
            handed = under_policy(handed, rules.unverified, rules.collected, due)
            entry.handed_in = handed
            if handed.note:
                entry.notes.append(handed.note)
            if not handed.verified and rules.unverified == "flag":
                entry.notes.append(flag(handed, due))
        if not task_files(entry.folder):
            entry.problem = f"no task files ({TASK_FILES[0]} ... {TASK_FILES[-1]}) handed in"


def unreadable_hand_in(source: Path, error: Exception) -> str:
    """The row's problem for a hand-in the intake could not read: what raised, in short
    (no other hand-in is affected)."""
    said = readable(str(error)).replace(str(source.parent), "").strip() or "no details"
    return (f"not graded: {readable(source.name)} could not be read "
            f"({type(error).__name__}: {said[:300]})")  # fmt: skip


def unlisted(identifier: str, source: Path) -> str:
    """The row's problem for a hand-in whose id no roster line gives."""
    return (f"not graded: {readable(source.name)} was handed in under the id "
            f"{identifier!r}, {NOT_ON_ROSTER}; add a roster line 'id,folder' for it if it is "
            "a student's")  # fmt: skip


def _not_from(source: str, form: str) -> HandIn:
    return unreadable(source, f"--handed-in {source} does not apply to {form}")


def _repository_of(folder: Path, given_in: Path) -> Path | None:
    """The repository ``folder`` is (or lies in, below the folder ``given_in``), if any."""
    for place in (folder, *folder.parents):
        if is_repository(place):
            return place
        if place == given_in or given_in not in place.parents:
            return None
    return None


def from_paths(paths: Iterable[Path], rules: Rules | None = None,
               known: set[str] | None = None) -> Intake:  # fmt: skip
    """The submissions at ``paths``, each under the id its path gives (see the module);
    with ``known`` (the roster's ids) an id not among them is refused."""
    paths = [Path(path) for path in paths]
    if not paths:
        raise ValueError("give at least one submission folder or zip file")
    missing = [str(path) for path in paths if not os.path.lexists(path)]
    if missing:
        raise FileNotFoundError(f"no submission at {', '.join(missing)}")
    placed = list(dict.fromkeys(Path(os.path.abspath(path)) for path in paths))  # each once
    base = Path(os.path.commonpath([path.parent for path in placed]))
    intake = Intake(rules)
    for path in placed:
        intake.add(_path_id(path, base), path, given_in=base, known=known)
    return intake


def from_roster(roster: Path, rules: Rules | None = None) -> Intake:
    """The submissions a roster lists (`roster`: a header line, then ``id,folder`` rows,
    paths relative to the roster's folder); a student with no folder given, or nothing at
    it, is `Entry.absent`."""
    students = read_roster(roster)
    if not any(student.folder for student in students):
        raise ValueError(f"{roster} names no folder or zip file: give a 'folder' column")
    intake = Intake(rules)
    for student in students:
        if student.folder is None or not os.path.lexists(student.folder):
            intake.add_absent(student.id, student.folder)
        else:
            intake.add(student.id, student.folder)
    for path in beside_the_roster(students):
        intake.add(_path_id(path, path.parent), path, known=set())
    return intake


def beside_the_roster(students: list[Student]) -> list[Path]:
    """The hand-ins no roster line names in the folder that holds the roster's hand-ins: a
    zip file, or a folder with task files (in itself or its ``assignments/``, or a git
    repository), hidden names and the course's own clone (its templates) left out."""
    listed = [Path(os.path.abspath(s.folder)) for s in students if s.folder is not None]
    if not listed:
        return []
    folder = Path(os.path.commonpath([path.parent for path in listed]))
    named = {place for path in (*listed, PROJECT_ROOT) for place in (path, *path.parents)}
    try:
        items = sorted(folder.iterdir())
    except OSError:  # no folder there, or not one to read: nothing beside to name
        return []
    found = []
    for item in items:
        if item in named or item.name.startswith(".") or item.is_symlink():
            continue
        if (item.suffix.lower() == ".zip" and item.is_file()) or _holds_a_hand_in(item):
            found.append(item)
    return found


def _holds_a_hand_in(folder: Path) -> bool:
    """Whether ``folder`` (a real folder) holds task files or is a git repository."""
    if not folder.is_dir() or folder.is_symlink():
        return False
    return is_repository(folder) or bool(task_files(folder / graded_part(folder)))


def taken_in(paths: list[Path], roster: Path | None, rules: Rules | None = None) -> Intake:
    """The class as the commands take it in: the roster's folders when no ``paths`` are
    given, else the ``paths`` (with a roster too, a path's id not on it is `unlisted`, and
    a roster student no path is for is absent)."""
    if not paths:
        return from_roster(roster, rules)
    students = read_roster(roster) if roster else []
    intake = from_paths(paths, rules, {student.id for student in students} if roster else None)
    handed = {entry.id for entry in intake.entries}
    for student in (s for s in students if s.id not in handed):
        intake.add_absent(student.id, None)
    return intake


def _path_id(path: Path, base: Path) -> str:
    """``path`` relative to ``base`` without a trailing 'assignments' or '.zip'."""
    parts = list(path.relative_to(base).parts) if path != base else [path.name]
    if len(parts) > 1 and parts[-1] == BUNDLE_FOLDER:
        parts.pop()
    elif parts == [BUNDLE_FOLDER] and path.parent.name:
        parts = [path.parent.name]
    if path.suffix.lower() == ".zip":
        parts[-1] = parts[-1][: -len(".zip")] or parts[-1]
    return "/".join(readable(part) for part in parts)
