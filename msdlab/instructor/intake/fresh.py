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
LEFT_OUT = " was left out: "
"""What a note on a file the intake did not take says after the file's name."""


class Refused(ValueError):
    """A submission the intake does not take at all (its message says why, to the instructor)."""


class FreshFolder:
    """A new folder of plain files; ``notes`` say what was left out of it and why."""

    def __init__(self, path: Path) -> None:
        path.mkdir(parents=True)
        self.path = path
        self.notes: list[str] = []
        self._bytes = 0

    def add(self, name: str, data: bytes) -> None:
        """Write ``data`` as the file ``name`` (one plain part), unless a bound is passed."""
        if len(data) > MAX_FILE_BYTES:
            self.leave_out(name, f"larger than {MAX_FILE_BYTES} bytes")
        elif (
            len(list(self.path.iterdir())) >= MAX_FILES or self._bytes + len(data) > MAX_TOTAL_BYTES
        ):
            self.leave_out(name, f"more than {MAX_FILES} files or {MAX_TOTAL_BYTES} bytes in all")
        else:
            (self.path / name).write_bytes(data)
            self._bytes += len(data)

    def clear(self) -> None:
        """Empty the folder again (what was written is not what is graded)."""
        shutil.rmtree(self.path)
        self.__init__(self.path)

    def leave_out(self, name: str, why: str) -> None:
        """Note that ``name`` was not taken, and why (only for files that could matter)."""
        if name.endswith(".py") or name == BUNDLE_FOLDER:
            self.notes.append(f"{readable(name)}{LEFT_OUT}{why}")


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
