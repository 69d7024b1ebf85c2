"""When a submission was handed in, read from the source that knows (``--handed-in``).

- ``gradescope``: ``created_at`` in Gradescope's ``submission_metadata.json`` beside the
  task files (or in the submission's folder or zip).
- ``git``: the last commit of the submission's repository (GitHub Classroom) made no later
  than the student's cutoff; the files of that commit are the ones graded. Its time is the
  committer date, which the student's machine set.
- ``zip``: the newest time among the zip's task files (a zip entry without the extended
  timestamp holds wall-clock time without a zone: it is read in the course's time zone).
- ``mtime``: the newest modification time of the task files (of the zip file itself for a
  zip); copying without keeping times (``cp`` without ``-p``) resets it.
- ``auto`` (the default): ``gradescope`` where the metadata file is, else ``git`` for a
  repository, ``zip`` for a zip file, ``mtime`` otherwise.
"""

from __future__ import annotations

import json
import os
import struct
import subprocess
import zipfile
from dataclasses import dataclass
from datetime import datetime, timezone, tzinfo
from pathlib import Path, PurePosixPath

from .intake import Entry

SOURCES = ("auto", "gradescope", "git", "zip", "mtime")
METADATA = "submission_metadata.json"
NAMES = {
    "gradescope": "Gradescope's submission time",
    "git": "last commit",
    "zip": "zip entry times",
    "mtime": "file modification time",
}
_EXTENDED_TIMESTAMP = 0x5455
_GIT = ["git", "-c", "safe.directory=*", "-c", "core.fsmonitor=", "-c", "core.hooksPath=/dev/null"]


@dataclass
class HandIn:
    """When the submission was handed in (None: not known, ``note`` says why) and how that
    was read; ``folder`` is what to grade instead of the entry's (a commit's files)."""

    time: datetime | None
    source: str
    note: str | None = None
    folder: Path | None = None


def handed_in(
    entry: Entry, source: str, zone: tzinfo | None, cutoff: datetime | None, scratch: Path
) -> HandIn:
    """When ``entry`` was handed in, by ``source`` (see the module); ``cutoff`` bounds the
    commits taken; ``scratch`` is a folder for a commit's files."""
    if source == "auto":
        source = _automatic(entry)
    try:
        if source == "gradescope":
            return HandIn(_gradescope_time(entry), NAMES[source])
        if source == "git":
            return _last_commit(entry, cutoff, scratch)
        if source == "zip":
            return HandIn(_zip_time(entry.source, zone), NAMES[source])
        return HandIn(_modification_time(entry), NAMES["mtime"])
    except (OSError, ValueError, KeyError, zipfile.BadZipFile, subprocess.SubprocessError) as error:
        return HandIn(None, NAMES[source], f"hand-in time unknown ({NAMES[source]}): {error}")


def _automatic(entry: Entry) -> str:
    if _metadata_file(entry) is not None:
        return "gradescope"
    if entry.source.is_dir() and (entry.source / ".git").exists():
        return "git"
    return "zip" if zipfile.is_zipfile(entry.source) else "mtime"


def _metadata_file(entry: Entry) -> Path | None:
    for folder in (entry.folder, entry.folder.parent, entry.source):
        if folder.is_dir() and (folder / METADATA).is_file():
            return folder / METADATA
    return None


def _gradescope_time(entry: Entry) -> datetime:
    path = _metadata_file(entry)
    if path is None:
        raise FileNotFoundError(f"no {METADATA} in {entry.source.name}")
    created = json.loads(path.read_text(encoding="utf-8")).get("created_at")
    if not isinstance(created, str):
        raise ValueError(f"{METADATA} has no created_at time")
    return _instant(created)


def _instant(text: str) -> datetime:
    """An ISO 8601 time with its offset (``Z`` too) as an aware datetime."""
    moment = datetime.fromisoformat(text.strip().replace("Z", "+00:00"))
    if moment.tzinfo is None:
        raise ValueError(f"{text!r} has no offset")
    return moment


def _zip_time(archive: Path, zone: tzinfo | None) -> datetime:
    with zipfile.ZipFile(archive) as bundle:
        members = [m for m in bundle.infolist() if not m.is_dir()]
        tasks = [m for m in members if PurePosixPath(m.filename).name.startswith("task")]
        if not members:
            raise ValueError(f"{archive.name} holds no files")
        return max(_entry_time(member, zone) for member in tasks or members)


def _entry_time(member: zipfile.ZipInfo, zone: tzinfo | None) -> datetime:
    """The entry's UTC time from its extended timestamp, else its wall-clock time in ``zone``."""
    extra = member.extra
    while len(extra) >= 4:
        kind, size = struct.unpack("<HH", extra[:4])
        body, extra = extra[4 : 4 + size], extra[4 + size :]
        if kind == _EXTENDED_TIMESTAMP and len(body) >= 5 and body[0] & 1:
            return datetime.fromtimestamp(struct.unpack("<i", body[1:5])[0], timezone.utc)
    wall = datetime(*member.date_time)
    return wall.replace(tzinfo=zone) if zone is not None else wall.astimezone()


def _modification_time(entry: Entry) -> datetime:
    if entry.source.is_file():
        paths = [entry.source]
    else:
        paths = [p for p in entry.folder.glob("task*.py") if p.is_file() and not p.is_symlink()]
    if not paths:
        raise FileNotFoundError("no task files to read the time of")
    newest = max(os.stat(path).st_mtime for path in paths)
    return datetime.fromtimestamp(newest, timezone.utc)


def _last_commit(entry: Entry, cutoff: datetime | None, scratch: Path) -> HandIn:
    """The last commit no later than ``cutoff``; its task files are copied to ``scratch``."""
    repository = entry.source
    if not (repository / ".git").exists():
        raise FileNotFoundError(f"{repository.name} is not a git repository")
    bound = ["--before", cutoff.isoformat()] if cutoff is not None else []
    last = _git(repository, "log", "-1", "--format=%H %cI", *bound, "HEAD").split()
    if not last:
        raise ValueError("no commit before the cutoff")
    commit, time = last
    newest = _git(repository, "log", "-1", "--format=%H", "HEAD").strip()
    inside = entry.folder.relative_to(repository).as_posix()
    target = scratch / commit
    target.mkdir(parents=True, exist_ok=True)
    listing = _git(repository, "ls-tree", "-z", f"{commit}:{inside}" if inside != "." else commit)
    for line in filter(None, listing.split("\0")):
        mode, kind, _, name = line.split(None, 3)
        if kind == "blob" and mode in ("100644", "100755") and name.endswith(".py"):
            path = f"{inside}/{name}" if inside != "." else name
            (target / name).write_bytes(_git_bytes(repository, "show", f"{commit}:{path}"))
    note = None
    if newest != commit:
        note = f"commits after the cutoff ignored; graded commit {commit[:10]} of {time}"
    return HandIn(_instant(time), NAMES["git"], note, target)


def _git(repository: Path, *arguments: str) -> str:
    return _git_bytes(repository, *arguments).decode("utf-8", errors="replace")


def _git_bytes(repository: Path, *arguments: str) -> bytes:
    done = subprocess.run(
        [*_GIT, "-C", str(repository), *arguments],
        capture_output=True,
        timeout=60,
        stdin=subprocess.DEVNULL,
    )
    if done.returncode != 0:
        message = done.stderr.decode(errors="replace").strip().splitlines()
        raise ValueError(f"git {arguments[0]}: {message[-1] if message else 'failed'}")
    return done.stdout
