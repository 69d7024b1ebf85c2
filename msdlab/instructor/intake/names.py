r"""Names at the intake boundary: a student's id as readable text, a file's name checked.

Ids are readable text (a folder name that is not valid UTF-8 keeps its readable part,
the rest becomes U+FFFD); `file_stem` makes from an id a file name of bounded length
that is unique too. Where a path must name its folder exactly (the grades' ``source``
column), `escaped` writes each byte that is not UTF-8 as ``\xNN`` and a backslash as
``\\``; `unescaped` gives the path back.

A name inside a submission (a zip entry, a commit's tree, a folder's file) is taken
only as one plain part: `unsafe_name` says why one is not (an absolute path, ``..``,
a ``.git`` folder, a separator or a NUL byte).
"""

from __future__ import annotations

import hashlib
import os
import re

MAX_STEM = 60
MAX_POINTS_ID = "(max points)"
"""The gradebook's row of the points each column is worth; no submission may take this id."""
FORMULA_STARTS = ("'", "=", "+", "-", "@")
"""An id starting with one of these would change on a spreadsheet's or the CSV's round trip."""


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


def id_problem(identifier: str) -> str | None:
    """Why ``identifier`` cannot be a student's id, or None: empty, spaces around it, the
    gradebook's reserved row, or a first character a spreadsheet reads as a formula."""
    if not identifier.strip():
        return "an empty id"
    if identifier != identifier.strip():
        return f"the id {identifier!r} has spaces around it"
    if identifier == MAX_POINTS_ID:
        return f"{MAX_POINTS_ID!r} is the gradebook's row of maximum points"
    if identifier.startswith(FORMULA_STARTS):
        return (
            f"the id {identifier!r} starts with {identifier[0]!r}, which a spreadsheet reads "
            "as a formula or drops"
        )
    return None


def lookalike(identifier: str) -> str:
    """The form two ids share when they differ only in case or surrounding spaces."""
    return identifier.strip().casefold()


def unsafe_name(name: str) -> str | None:
    """Why the path ``name`` (parts separated by ``/``) inside a submission is not taken, or
    None: absolute, a ``..`` or ``.git`` part, a backslash or NUL byte, or empty."""
    if not name or "\0" in name or "\\" in name:
        return f"the name {name!r} is not a plain file name"
    if name.startswith("/") or re.match(r"^[A-Za-z]:", name):
        return f"the name {name!r} is an absolute path"
    parts = [part for part in name.split("/") if part not in ("", ".")]
    if ".." in parts:
        return f"the name {name!r} leads out of its folder (..)"
    if any(part.rstrip(". ").casefold() == ".git" for part in parts):
        return f"the name {name!r} is inside a .git folder"
    return None
