"""Every file the instructor's commands write, written without following a link.

A grades file, gradebook, feedback file, report or export that is a symbolic link would
send this class's rows wherever the link points (another course's gradebook, a student's
folder on a shared machine). So an output path that is a link, or a folder msdlab fills
(the feedback's ``students/`` and ``instructor/``) that is one, is refused with a clear
error (`not_a_link`), and a file is written whole into a new
file beside it and renamed over the old one (`write_text`): a rename replaces a link
made in between instead of writing through it, and a crash leaves the old file or the
whole new one.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


class LinkRefused(ValueError):
    """An output path that is a symbolic link (its message says which, and the fix)."""


def not_a_link(path: Path, what: str = "output") -> Path:
    """``path``, after checking that it is not a symbolic link (the folders it lies in
    are the instructor's choice: ``/tmp`` is a link on some systems)."""
    path = Path(path)
    if path.is_symlink():
        raise LinkRefused(
            f"the {what} {path} is a symbolic link (to {os.readlink(path)}); msdlab writes "
            "nothing through a link: remove the link or give another path"
        )
    return path


def write_text(path: Path, text: str, what: str = "output", durable: bool = False) -> None:
    """Write ``text`` as a UTF-8 file at ``path`` (not a link), atomically."""
    write_bytes(path, text.encode("utf-8"), what, durable)


def write_bytes(path: Path, data: bytes, what: str = "output", durable: bool = False) -> None:
    """Write ``data`` at ``path`` (not a link), atomically: a file beside it renamed over it
    (``durable``: on the disk before the rename, for a record such as the grades file)."""
    path = not_a_link(path, what)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(handle, "wb") as out:
            out.write(data)
            if durable:
                out.flush()
                os.fsync(out.fileno())
        os.chmod(temporary, 0o644)
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
