r"""Taking in a class's submissions: which folder is whose, under a unique readable id.

A submission is given as a folder laid out like ``assignments/``, a folder
holding ``assignments/`` (a student who handed in the whole bundle), or a zip
file of either. Its id is its path relative to the common parent of all the
submissions given, without a trailing ``assignments`` (``class/alice/assignments``
-> ``alice``), or the id a roster gives it (``--roster FILE``: CSV rows
``id,folder-or-zip``, paths relative to the roster's folder, after an optional header
line such as ``student,submission``).

Ids are readable text (a folder name that is not valid UTF-8 keeps its
readable part, the rest becomes U+FFFD) and never repeat; `file_stem` makes
from an id a file name of bounded length that is unique too. Where a path must
name its folder exactly (the grades' ``source`` column), `escaped` writes each
byte that is not UTF-8 as ``\xNN`` and a backslash as ``\\``; `unescaped`
gives the path back.

A submission that is a symbolic link, lies below one, or resolves outside the
folder it was handed in is not followed (`link_problem`), nor is a zip file
holding a link: such an entry has a problem and no folder to grade.
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import os
import re
import shutil
import tempfile
import zipfile
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from ..course import TASKS

BUNDLE_FOLDER = "assignments"
MAX_ZIP_BYTES = 50_000_000
MAX_STEM = 60
MAX_POINTS_ID = "(max points)"
"""The gradebook's row of the points each column is worth; no submission may take this id."""


@dataclass
class Entry:
    """One submission as handed in: its id, the folder to grade, and notes or a problem.

    ``problem`` is set when there is nothing to grade (no task files at all); such
    a submission gets a row with the problem and makes the run's exit status 1, unless
    the student is ``absent`` (the roster names them, nothing is at their path).
    """

    id: str
    source: Path
    folder: Path
    notes: list[str] = field(default_factory=list)
    problem: str | None = None
    absent: bool = False
    """True for a roster's student who handed in nothing (a row of 0 points)."""


def task_files(folder: Path) -> list[str]:
    """The task files ``task1.py`` ... present in ``folder``."""
    return [f"task{t}.py" for t in TASKS if (folder / f"task{t}.py").exists()]


def readable(name: str) -> str:
    """``name`` as text that can be printed and written as UTF-8 (bad bytes become U+FFFD)."""
    return os.fsencode(name).decode("utf-8", errors="replace")


def escaped(path: str) -> str:
    """``path`` as UTF-8 text naming it exactly: bytes that are not UTF-8 become ``\\xNN``,
    a backslash becomes two; `unescaped` reverses it."""
    text = os.fsdecode(os.fsencode(path))  # undecodable bytes as surrogates U+DC80..U+DCFF
    return "".join(_escaped_character(char) for char in text)


def _escaped_character(char: str) -> str:
    if char == "\\":
        return "\\\\"
    if 0xDC80 <= ord(char) <= 0xDCFF:  # the byte 0x80..0xFF that was not UTF-8
        return f"\\x{ord(char) - 0xDC00:02x}"
    return char


def unescaped(text: str) -> str:
    """The path that `escaped` wrote as ``text`` (undecodable bytes back as surrogates)."""
    return re.sub(
        r"\\(\\|x([0-9a-f]{2}))",
        lambda m: "\\" if m.group(2) is None else chr(0xDC00 + int(m.group(2), 16)),
        text,
    )


def file_stem(identifier: str) -> str:
    """A file name (no suffix) for ``identifier``: letters, digits, ``._-`` only, at most
    `MAX_STEM` characters; any change to the id adds a short hash, so stems stay unique."""
    cleaned = re.sub(r"[^\w.-]+", "_", identifier).strip("._") or "submission"
    if cleaned == identifier and len(cleaned) <= MAX_STEM:
        return cleaned
    digest = hashlib.sha1(os.fsencode(identifier)).hexdigest()[:8]
    return f"{cleaned[: MAX_STEM - 9]}-{digest}"


class Intake(contextlib.AbstractContextManager):
    """The entries of one grading run; unpacked zip files live until `close`."""

    def __init__(self) -> None:
        self.entries: list[Entry] = []
        self._scratch: Path | None = None

    def close(self) -> None:
        if self._scratch is not None:
            shutil.rmtree(self._scratch, ignore_errors=True)
            self._scratch = None

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def add(self, identifier: str, source: Path, given_in: Path | None = None) -> Entry:
        """Add the submission at ``source`` (folder or zip) under ``identifier``; a link, or a
        path leading outside the folder ``given_in`` (default: its parent), is not followed."""
        identifier = readable(identifier).strip()
        if not identifier or identifier == MAX_POINTS_ID:
            raise ValueError(f"{source}: {identifier!r} cannot be a submission id")
        if identifier in {entry.id for entry in self.entries}:
            raise ValueError(f"two submissions have the id {identifier!r}: give unique ids")
        source = Path(os.path.abspath(source))
        refused = link_problem(source, given_in or source.parent)
        if refused is not None:
            entry = Entry(identifier, source, source, problem=refused)
        elif source.is_file() and zipfile.is_zipfile(source):
            entry = self._from_zip(identifier, source)
        elif source.is_dir():
            entry = _from_folder(identifier, source, source)
        else:
            raise FileNotFoundError(f"submission {source} is neither a folder nor a zip file")
        self.entries.append(entry)
        return entry

    def add_absent(self, identifier: str, expected: Path | None) -> Entry:
        """Add a student who handed in nothing (nothing at ``expected``, or no path given)."""
        identifier = readable(identifier).strip()
        if identifier in {entry.id for entry in self.entries} or identifier == MAX_POINTS_ID:
            raise ValueError(f"{identifier!r} cannot be a submission id: give unique ids")
        where = f" (no folder or zip file at {readable(str(expected))})" if expected else ""
        entry = Entry(identifier, expected or Path(), expected or Path(),
                      problem=f"nothing handed in{where}", absent=True)  # fmt: skip
        self.entries.append(entry)
        return entry

    def _from_zip(self, identifier: str, source: Path) -> Entry:
        if self._scratch is None:
            self._scratch = Path(tempfile.mkdtemp(prefix="msdlab-intake-"))
        target = self._scratch / str(len(self.entries))
        try:
            _unpack(source, target)
        except (zipfile.BadZipFile, ValueError, OSError) as error:
            return Entry(identifier, source, target, problem=f"{source.name} not unpacked: {error}")
        top = [path for path in target.iterdir() if not path.name.startswith(("__MACOSX", "."))]
        folder = top[0] if len(top) == 1 and top[0].is_dir() and not task_files(target) else target
        return _from_folder(identifier, source, folder)


def from_paths(paths: Iterable[Path]) -> Intake:
    """The submissions at ``paths``, each under the id its path gives (see the module)."""
    paths = [Path(path) for path in paths]
    if not paths:
        raise ValueError("give at least one submission folder or zip file")
    missing = [str(path) for path in paths if not path.exists()]
    if missing:
        raise FileNotFoundError(f"no submission at {', '.join(missing)}")
    placed = list(dict.fromkeys(Path(os.path.abspath(path)) for path in paths))  # each once
    base = Path(os.path.commonpath([path.parent for path in placed]))
    ids = [_path_id(path, base) for path in placed]
    intake = Intake()
    taken: set[str] = set()
    for path, identifier in zip(placed, ids):
        unique, count = identifier, 1
        while unique in taken:
            count += 1
            unique = f"{identifier}-{count}"
        taken.add(unique)
        intake.add(unique, path, given_in=base)
    return intake


def link_problem(path: Path, given_in: Path) -> str | None:
    """Why the submission at ``path`` is not followed, or None: it is a symbolic link, lies
    below one, or resolves outside the folder ``given_in`` it was handed in."""
    path, given_in = Path(os.path.abspath(path)), Path(os.path.abspath(given_in))
    for place in (path, *path.parents):
        if place == given_in or given_in not in place.parents:
            break
        if place.is_symlink():
            target = readable(os.readlink(place))
            return (
                f"not graded: {readable(place.name)} is a symbolic link (to {target}); links "
                "are not followed, hand in the folder or zip file itself"
            )
    if not path.resolve().is_relative_to(given_in.resolve()):
        return (
            f"not graded: {readable(path.name)} resolves to {readable(str(path.resolve()))}, "
            f"outside the folder {readable(str(given_in))} it was handed in"
        )
    return None


def from_roster(roster: Path) -> Intake:
    """The submissions a roster CSV lists as ``id,folder-or-zip`` (paths relative to the
    roster's folder; a first line naming the columns, such as ``student,submission``, is a
    header)."""
    roster = Path(roster)
    if not roster.is_file():
        raise FileNotFoundError(f"no roster file at {roster}")
    intake = Intake()
    with roster.open(newline="", encoding="utf-8-sig") as handle:
        for number, row in enumerate(csv.reader(handle), start=1):
            cells = [cell.strip() for cell in row]
            if not any(cells) or cells[0].startswith("#") or (number == 1 and _header(cells)):
                continue
            where = f"roster {roster}, line {number}"
            if not cells[0]:
                raise ValueError(
                    f"{where}: '{','.join(row)}' is not 'id,folder-or-zip' (the submission's "
                    "id, then its folder or zip file)"
                )
            path = Path(cells[1] if len(cells) > 1 else "").expanduser()
            path = path if path.is_absolute() else roster.parent / path
            if len(cells) < 2 or not cells[1] or not path.exists():
                intake.add_absent(cells[0], path if len(cells) > 1 and cells[1] else None)
                continue
            intake.add(cells[0], path)
    if not intake.entries:
        raise ValueError(f"{roster} lists no submissions (rows of 'id,folder-or-zip')")
    return intake


ID_HEADINGS = {"id", "student", "studentid", "name", "login", "username", "user", "email"}
PATH_HEADINGS = {"folder", "folderorzip", "path", "submission", "zip", "source", "file"}


def _header(cells: list[str]) -> bool:
    """True if ``cells`` name a roster's columns (``id,folder``, ``Student,Submission``...)."""
    words = [re.sub(r"[\s_-]+", "", cell.lower()) for cell in cells]
    return words[0] in ID_HEADINGS or (len(words) > 1 and words[1] in PATH_HEADINGS)


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


def _from_folder(identifier: str, source: Path, folder: Path) -> Entry:
    """The entry of a folder: graded from its ``assignments/`` when it holds only that."""
    entry = Entry(identifier, source, folder)
    inner = folder / BUNDLE_FOLDER
    if inner.is_symlink():
        entry.problem = link_problem(inner, folder)
    elif not task_files(folder) and inner.is_dir():
        entry.folder = inner  # the bundle handed in whole: its task files, without a note
    if entry.problem is None and not task_files(entry.folder):
        entry.problem = f"no task files (task{TASKS[0]}.py ... task{TASKS[-1]}.py) handed in"
    return entry


def _unpack(archive: Path, target: Path) -> None:
    """Extract ``archive`` into ``target``, refusing absolute or escaping paths and zip bombs."""
    with zipfile.ZipFile(archive) as bundle:
        members = bundle.infolist()
        if sum(member.file_size for member in members) > MAX_ZIP_BYTES:
            raise ValueError(f"unpacks to more than {MAX_ZIP_BYTES} bytes")
        for member in members:
            name = PurePosixPath(member.filename)
            if name.is_absolute() or ".." in name.parts:
                raise ValueError(f"it holds a path outside its folder: {member.filename}")
            if (member.external_attr >> 16) & 0o170000 == 0o120000:
                raise ValueError(f"it holds a symbolic link, not followed: {member.filename}")
            if member.is_dir():
                continue  # folders come with their files
            destination = target.joinpath(*name.parts)
            destination.parent.mkdir(parents=True, exist_ok=True)
            with bundle.open(member) as data, destination.open("wb") as out:
                shutil.copyfileobj(data, out)
