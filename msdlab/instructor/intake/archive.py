"""A submission handed in as a zip file: its entries read as data, never unpacked in place.

Every entry's name is checked first: one that is absolute, climbs out (``..``) or lies in
a ``.git`` folder refuses the whole zip. Then the entries directly in its graded folder
(`fresh.graded_folder`) are written into the fresh folder; a link entry is left out, and
no entry is read past `fresh.MAX_FILE_BYTES` (a zip's own sizes are not trusted).
"""

from __future__ import annotations

import zipfile
from datetime import tzinfo
from pathlib import Path

from .fresh import MAX_FILE_BYTES, FreshFolder, Refused, graded_folder
from .names import unsafe_name
from .times import HandIn, zip_time

_LINK = 0o120000


def take_zip(archive: Path, fresh: FreshFolder, zone: tzinfo | None) -> HandIn:
    """Write the files of ``archive``'s graded folder into ``fresh``; return the time of
    its entries (set by the student's machine)."""
    try:
        with zipfile.ZipFile(archive) as bundle:
            members = bundle.infolist()
            for member in members:
                why = unsafe_name(member.filename)
                if why:
                    raise Refused(f"{archive.name} not taken: {why}")
            part = _graded(members)
            for member in _directly_in(members, part):
                _take(bundle, member, fresh)
            return zip_time(_directly_in(members, part) or members, zone)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, RuntimeError) as error:
        raise Refused(f"{archive.name} could not be read as a zip file: {error}") from None


def _graded(members: list[zipfile.ZipInfo]) -> str:
    names = [_name(member) for member in members]

    def inside(prefix: str) -> list[str]:
        return [n[len(prefix) :] for n in names if n.startswith(prefix) and n != prefix]

    return graded_folder(
        lambda prefix: {rest for rest in inside(prefix) if "/" not in rest},
        lambda prefix: sorted({rest.split("/", 1)[0] for rest in inside(prefix) if "/" in rest}),
    )


def _name(member: zipfile.ZipInfo) -> str:
    return member.filename.removeprefix("./")


def _directly_in(members: list[zipfile.ZipInfo], part: str) -> list[zipfile.ZipInfo]:
    """The file entries directly in the folder ``part`` of the zip."""
    found = []
    for member in members:
        name = _name(member)
        rest = name[len(part) :] if name.startswith(part) else None
        if rest and "/" not in rest and not member.is_dir():
            found.append(member)
    return found


def _take(bundle: zipfile.ZipFile, member: zipfile.ZipInfo, fresh: FreshFolder) -> None:
    name = member.filename.rsplit("/", 1)[-1]
    if (member.external_attr >> 16) & 0o170000 == _LINK:
        fresh.leave_out(name, "a symbolic link in the zip (links are not followed)")
        return
    with bundle.open(member) as data:
        fresh.add(name, data.read(MAX_FILE_BYTES + 1))
