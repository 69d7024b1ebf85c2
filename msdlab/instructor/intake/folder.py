"""A submission handed in as a folder: its plain files read without following a link.

A submission that is a symbolic link, lies below one, or resolves outside the folder it
was handed in is refused (`link_problem`): on a shared machine a student could otherwise
link their folder to another's work or to the course's solutions. Inside it, each file
is opened without following a link (``O_NOFOLLOW``) and taken only if it is a regular
file; links, devices and pipes are left out.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from .fresh import MAX_FILE_BYTES, FreshFolder, graded_folder
from .names import readable, unsafe_name


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


def graded_part(folder: Path) -> str:
    """The part of ``folder`` that is graded ('' itself, else ``assignments/`` or its one
    folder), looking at real folders only (a link to a folder is not one)."""
    return graded_folder(lambda prefix: _names(folder / prefix)[0],
                         lambda prefix: sorted(_names(folder / prefix)[1]))  # fmt: skip


def _names(folder: Path) -> tuple[set[str], set[str]]:
    """The regular files and the real folders directly in ``folder``."""
    files, folders = set(), set()
    try:
        with os.scandir(folder) as listing:
            for item in listing:
                if item.is_file(follow_symlinks=False):
                    files.add(item.name)
                elif item.is_dir(follow_symlinks=False):
                    folders.add(item.name)
    except OSError:
        pass
    return files, folders


def copy_files(folder: Path, fresh: FreshFolder) -> list[float]:
    """Write the regular files directly in ``folder`` into ``fresh``; return the task files'
    modification times (seconds)."""
    times = []
    with os.scandir(folder) as listing:
        items = sorted(listing, key=lambda item: item.name)
    for item in items:
        if item.is_dir(follow_symlinks=False):
            continue
        why = unsafe_name(item.name)
        data = None if why else _read_plain(Path(item.path))
        if data is None:
            fresh.leave_out(item.name, why or "not a regular file (a link is not followed)")
            continue
        fresh.add(item.name, data[0])
        if item.name.startswith("task") and item.name.endswith(".py"):
            times.append(data[1])
    return times


def _read_plain(path: Path) -> tuple[bytes, float] | None:
    """The bytes and modification time of ``path`` if it is a regular file (a link is
    not followed); at most one byte more than `MAX_FILE_BYTES` is read."""
    try:
        handle = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    try:
        status = os.fstat(handle)
        if not stat.S_ISREG(status.st_mode):
            return None
        with os.fdopen(os.dup(handle), "rb") as file:
            return file.read(MAX_FILE_BYTES + 1), status.st_mtime
    finally:
        os.close(handle)
