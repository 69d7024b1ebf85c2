"""When a submission was handed in, and who controls the record of that time.

Every hand-in time carries its source and who could have set it (`HandIn.control`):

- ``instructor``: Gradescope's ``submission_metadata.json`` where Gradescope puts it,
  beside the student's files (``/autograder/submission_metadata.json`` beside
  ``/autograder/submission/``), never among them; a copy among the student's files (in
  their folder, zip or repository) is theirs to write: ignored, and noted.
- ``student``: a commit's date, a zip entry's time, a file's modification time: the
  student's machine wrote them, and any student can set them to any time.
- ``unreadable``: no time could be read (a zip entry of month 0, metadata without a
  time, a repository without commits).

What a time that is not the instructor's gets is the instructor's choice
(``--unverified-time``, `UNVERIFIED_POLICIES`): ``flag`` (the default) takes it as read and
marks the row, the feedback and the summary; ``accept`` takes it as read without a mark;
``late`` charges the submission as handed in when the grading run took it in.
"""

from __future__ import annotations

import json
import struct
import zipfile
from dataclasses import dataclass, replace
from datetime import datetime, timezone, tzinfo
from pathlib import Path

INSTRUCTOR, STUDENT, UNREADABLE = "instructor", "student", "unreadable"
SOURCES = ("auto", "gradescope", "git", "zip", "mtime")
UNVERIFIED_POLICIES = ("flag", "accept", "late")
METADATA = "submission_metadata.json"
NAMES = {
    "gradescope": "Gradescope's submission time",
    "git": "last commit",
    "zip": "zip entry times",
    "mtime": "file modification time",
}
_EXTENDED_TIMESTAMP = 0x5455


@dataclass(frozen=True)
class HandIn:
    """When the submission was handed in (None: unreadable, ``note`` says why), from which
    source (`NAMES`), and who controls that record (``instructor``, ``student`` or
    ``unreadable``)."""

    time: datetime | None
    source: str
    control: str
    note: str | None = None

    @property
    def verified(self) -> bool:
        """Whether the time is one the student could not have set."""
        return self.control == INSTRUCTOR


def unreadable(source: str, why: str) -> HandIn:
    """A hand-in time that could not be read from ``source`` (a key of `NAMES`)."""
    return HandIn(
        None, NAMES[source], UNREADABLE, f"hand-in time unreadable ({NAMES[source]}): {why}"
    )


def gradescope_time(metadata: Path) -> HandIn:
    """``created_at`` in the ``submission_metadata.json`` Gradescope wrote at ``metadata``."""
    try:
        created = json.loads(metadata.read_text(encoding="utf-8")).get("created_at")
        return HandIn(instant(created), NAMES["gradescope"], INSTRUCTOR)
    except (OSError, ValueError, AttributeError, TypeError) as error:
        return unreadable("gradescope", f"{metadata.name} has no created_at time ({error})")


def instant(text: object) -> datetime:
    """An ISO 8601 time with its offset (``Z`` too) as an aware datetime."""
    if not isinstance(text, str):
        raise ValueError(f"{text!r} is not a time")
    moment = datetime.fromisoformat(text.strip().replace("Z", "+00:00"))
    if moment.tzinfo is None:
        raise ValueError(f"{text!r} has no offset")
    return moment


def zip_time(members: list[zipfile.ZipInfo], zone: tzinfo | None) -> HandIn:
    """The newest time among the zip's task files (all its files if it has none): set by
    the student's machine. An entry without the extended timestamp holds wall-clock time
    without a zone, read in ``zone`` (None: the grading machine's)."""
    files = [m for m in members if not m.is_dir()]
    tasks = [m for m in files if m.filename.rsplit("/", 1)[-1].startswith("task")]
    try:
        if not files:
            raise ValueError("the zip holds no files")
        return HandIn(max(_entry_time(m, zone) for m in tasks or files), NAMES["zip"], STUDENT)
    except (ValueError, OverflowError, OSError) as error:
        return unreadable("zip", str(error))


def _entry_time(member: zipfile.ZipInfo, zone: tzinfo | None) -> datetime:
    """The entry's UTC time from its extended timestamp, else its wall-clock time in ``zone``."""
    extra = member.extra
    while len(extra) >= 4:
        kind, size = struct.unpack("<HH", extra[:4])
        body, extra = extra[4 : 4 + size], extra[4 + size :]
        if kind == _EXTENDED_TIMESTAMP and len(body) >= 5 and body[0] & 1:
            return datetime.fromtimestamp(struct.unpack("<i", body[1:5])[0], timezone.utc)
    try:
        wall = datetime(*member.date_time)
    except ValueError:
        raise ValueError(f"{member.filename} has no valid time ({member.date_time})") from None
    return wall.replace(tzinfo=zone) if zone is not None else wall.astimezone()


def modification_time(seconds: list[float]) -> HandIn:
    """The newest of the task files' modification times (``seconds`` since the epoch)."""
    if not seconds:
        return unreadable("mtime", "no task files to read the time of")
    try:
        newest = datetime.fromtimestamp(max(seconds), timezone.utc)
    except (ValueError, OverflowError, OSError):
        return unreadable("mtime", f"{max(seconds):.0f} s since 1970 is no date a calendar holds")
    return HandIn(newest, NAMES["mtime"], STUDENT)


def under_policy(handed: HandIn, policy: str, collected: datetime, due: datetime) -> HandIn:
    """``handed`` as the instructor's ``policy`` for unverified times takes it
    (`UNVERIFIED_POLICIES`); ``collected``: when this grading run took the submission in;
    its note gives times in the zone of the ``due`` date."""
    if handed.verified or policy != "late":
        return handed
    read = shown(handed.time, due) if handed.time else "unreadable"
    note = (
        f"hand-in time not verified ({handed.source}: {read}, {_who(handed)}): charged as "
        f"handed in when it was taken in for grading, {shown(collected, due)} "
        "(--unverified-time late)"
    )
    return replace(handed, time=collected, note=note)


def flag(handed: HandIn, due: datetime) -> str:
    """The note that marks a time the grader could not verify (in the ``due`` date's zone)."""
    read = shown(handed.time, due) if handed.time else "none"
    return f"hand-in time not verified: {handed.source} ({read}) {_who(handed)}"


def shown(moment: datetime, due: datetime) -> str:
    """``moment`` to the minute on the clock of the ``due`` date's zone (`in_zone`)."""
    return in_zone(moment, due).isoformat(timespec="minutes")


def in_zone(moment: datetime, due: datetime) -> datetime:
    """``moment`` on the clock of the ``due`` date's zone (as read where that clock has no
    such date: a forged time at the end of year 9999)."""
    try:
        return moment.astimezone(due.tzinfo)
    except OverflowError:
        return moment


def _who(handed: HandIn) -> str:
    return "set by the student's machine" if handed.control == STUDENT else "unreadable"
