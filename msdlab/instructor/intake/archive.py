"""A submission handed in as a zip file: its entries read as data, never unpacked in place.

The bounds come first, from the zip's end record, before its directory is read: a zip of
more than `MAX_ENTRIES` entries, or whose directory is larger than `MAX_DIRECTORY_BYTES`
(its count can lie), is refused. Then each rule names what it did in the row:

- refused, the whole zip: an entry's name that is absolute, climbs out (``..``) or lies
  in a ``.git`` folder; two entries of one name in the graded folder (which one the
  student meant cannot be told);
- left out, with a note: a link entry, an encrypted entry, an entry whose stated size
  passes `fresh.MAX_FILE_BYTES` (not read), an entry that cannot be read (a bad
  checksum, an unknown compression);
- taken: every other entry directly in the graded folder (`fresh.graded_folder`), read
  to at most `fresh.MAX_FILE_BYTES` + 1 bytes (a zip's own sizes are not trusted).
"""

from __future__ import annotations

import collections
import struct
import zipfile
import zlib
from datetime import tzinfo
from pathlib import Path

from .fresh import MAX_FILE_BYTES, FreshFolder, Refused, graded_folder
from .names import readable, unsafe_name
from .times import HandIn, zip_time

MAX_ENTRIES = 5000
"""The most entries a zip handed in may hold (a course's bundle holds a few dozen)."""
MAX_DIRECTORY_BYTES = MAX_ENTRIES * 512
"""The largest central directory read (an entry's record is 46 bytes and its name)."""
_LINK = 0o120000
_END = b"PK\x05\x06"
_END_SIZE, _COMMENT_MAX, _ZIP64 = 22, 65535, 0xFFFF


def take_zip(archive: Path, fresh: FreshFolder, zone: tzinfo | None) -> HandIn:
    """Write the files of ``archive``'s graded folder into ``fresh`` (see the module);
    return the time of its entries (set by the student's machine)."""
    count, size = directory(archive)
    if count > MAX_ENTRIES or size > MAX_DIRECTORY_BYTES:
        more = " or more" if count == _ZIP64 else ""
        raise Refused(
            f"not graded: {readable(archive.name)} holds {count}{more} entries in a directory "
            f"of {size} bytes, more than the {MAX_ENTRIES} entries or {MAX_DIRECTORY_BYTES} "
            "bytes read; zip the assignments folder alone"
        )
    try:
        with zipfile.ZipFile(archive) as bundle:
            members = bundle.infolist()
            for member in members:
                why = unsafe_name(member.filename)
                if why:
                    raise Refused(f"{archive.name} not taken: {why}")
            part = _graded(members)
            taken = _directly_in(members, part)
            _refuse_twins(taken, archive)
            for member in taken:
                _take(bundle, member, fresh)
            return zip_time(taken or members, zone)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, RuntimeError) as error:
        raise Refused(f"{archive.name} could not be read as a zip file: {error}") from None


def directory(archive: Path) -> tuple[int, int]:
    """How many entries the zip's end record says it holds (a Zip64 zip's, 65535 or more,
    as 65535), and the size of its central directory in bytes (what reading it costs,
    whatever the count says)."""
    with archive.open("rb") as file:
        file.seek(0, 2)
        size = file.tell()
        file.seek(max(0, size - _END_SIZE - _COMMENT_MAX))
        tail = file.read()
    at = tail.rfind(_END)
    if at < 0 or len(tail) - at < _END_SIZE:
        raise Refused(f"{readable(archive.name)} could not be read as a zip file: no end record")
    on_disk, total, size = struct.unpack("<HHI", tail[at + 8 : at + 16])
    return max(on_disk, total), size


def _refuse_twins(members: list[zipfile.ZipInfo], archive: Path) -> None:
    """Refuse a zip whose graded folder names one file twice."""
    counts = collections.Counter(_name(member) for member in members)
    twins = sorted(name for name, count in counts.items() if count > 1)
    if twins:
        raise Refused(
            f"not graded: {readable(archive.name)} holds {readable(twins[0])} "
            f"{counts[twins[0]]} times (which one was meant cannot be told); zip the folder "
            "again"
        )


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
    why = _left_out(member)
    if why is not None:
        fresh.leave_out(name, why)
        return
    try:
        with bundle.open(member) as data:
            fresh.add(name, data.read(MAX_FILE_BYTES + 1))
    except (zipfile.BadZipFile, NotImplementedError, zlib.error, EOFError, OSError) as error:
        fresh.leave_out(name, f"could not be read from the zip ({error})")


def _left_out(member: zipfile.ZipInfo) -> str | None:
    """Why the entry is left out unread (see the module), or None."""
    if (member.external_attr >> 16) & 0o170000 == _LINK:
        return "a symbolic link in the zip (links are not followed)"
    if member.flag_bits & 0x1:
        return "encrypted in the zip (it cannot be read without its password)"
    if member.file_size > MAX_FILE_BYTES:
        return f"larger than {MAX_FILE_BYTES} bytes (not read)"
    return None
