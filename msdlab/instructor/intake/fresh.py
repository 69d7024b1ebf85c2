"""The fresh folder a submission's plain files are written into, and which folder of a
hand-in is graded.

Whatever the form of a hand-in (folder, zip, commit), the intake writes the regular
files of its graded folder, by name, into a new folder of its own: no link is copied or
followed, a name that is not one plain part is refused (`names.unsafe_name`), and each
file (`MAX_FILE_BYTES`), the files' count (`MAX_FILES`) and their sum (`MAX_TOTAL_BYTES`)
are bounded. Everything after the intake (the sandbox, similarity, the gradebook's
fingerprint) reads only this folder.
"""

from __future__ import annotations

import collections
import shutil
from collections.abc import Callable
from pathlib import Path

from ...course import TASKS
from .names import readable

MAX_FILE_BYTES = 1_000_000
MAX_FILES = 200
MAX_TOTAL_BYTES = 20_000_000
BUNDLE_FOLDER = "assignments"
TASK_FILES = tuple(f"task{task}.py" for task in TASKS)
MAX_NOTES = 5
"""Files left out that get a note each; the rest are counted in one."""
LEFT_OUT = " was left out: "
"""What a note on a file the intake did not take says after the file's name."""


class Refused(ValueError):
    """A submission the intake does not take at all (its message says why, to the instructor)."""


class FreshFolder:
    """A new folder of plain files; ``notes`` say what was left out of it and why."""

    def __init__(self, path: Path) -> None:
        path.mkdir(parents=True)
        self.path = path
        self._left_out: list[tuple[str, str]] = []
        self._bytes = self._files = 0

    @property
    def notes(self) -> list[str]:
        """What was left out: a note per file for the first `MAX_NOTES`, then one counting
        the rest by reason (a zip of 10 000 entries gets a few lines, not 10 000)."""
        shown = [f"{readable(name)}{LEFT_OUT}{why}" for name, why in self._left_out[:MAX_NOTES]]
        rest = collections.Counter(why for _, why in self._left_out[MAX_NOTES:])
        if rest:
            counted = "; ".join(f"{count} {why}" for why, count in rest.most_common(3))
            others = f" and {len(rest) - 3} other reasons" if len(rest) > 3 else ""
            shown.append(f"and {rest.total()} more files left out ({counted}{others})")
        return shown

    def add(self, name: str, data: bytes) -> None:
        """Write ``data`` as the file ``name`` (one plain part), unless a bound is passed."""
        if len(data) > MAX_FILE_BYTES:
            self.leave_out(name, f"larger than {MAX_FILE_BYTES} bytes")
        elif self._files >= MAX_FILES or self._bytes + len(data) > MAX_TOTAL_BYTES:
            self.leave_out(name, f"more than {MAX_FILES} files or {MAX_TOTAL_BYTES} bytes in all")
        else:
            (self.path / name).write_bytes(data)
            self._bytes += len(data)
            self._files += 1

    def clear(self) -> None:
        """Empty the folder again (what was written is not what is graded)."""
        shutil.rmtree(self.path)
        self.__init__(self.path)

    def leave_out(self, name: str, why: str) -> None:
        """Note that ``name`` was not taken, and why (only for files that could matter)."""
        if name.endswith(".py") or name == BUNDLE_FOLDER:
            self._left_out.append((name, why))


def graded_folder(
    files: Callable[[str], set[str]], folders: Callable[[str], list[str]], top: str = ""
) -> str:
    """Which folder of a hand-in holds its task files: its top, its ``assignments/``, or
    (once) its one folder, e.g. the folder a zip was made of. ``files(prefix)`` and
    ``folders(prefix)`` name what lies directly in the folder ``prefix`` ('' the top, else
    ending in ``/``)."""
    if files(top) & set(TASK_FILES):
        return top
    inner = f"{top}{BUNDLE_FOLDER}/"
    if BUNDLE_FOLDER in folders(top) and files(inner) & set(TASK_FILES):
        return inner
    wrapped = [f for f in folders(top) if not f.startswith(("__MACOSX", "."))]
    if top == "" and len(wrapped) == 1 and not files(top) & set(TASK_FILES):
        return graded_folder(files, folders, f"{wrapped[0]}/")
    return top
