"""The student pages of the documentation, as plain Markdown for the student release.

The release holds no built site: `write` copies the student pages (``docs/student/*.md``)
into the release's ``docs/``, readable in any Markdown viewer (a forge's file view, an
editor): the site's table of contents goes, so does what a page marks as the course's only
(between ``<!-- course only -->`` and ``<!-- end course only -->``: how a clone of the
course works, which the release is not), a MyST role becomes its code text, a picture
of the site's comes along, a link stays where its target is in the release (the
notebooks, another student page) and becomes its plain text where it is not (the
engine's pages, the gallery).
"""

from __future__ import annotations

import re
import shutil
from functools import partial
from pathlib import Path

PAGES = Path("docs") / "student"
"""Where the student pages are in a course folder."""

TARGET = "docs"
"""Where they go in the release."""

PICTURES = "pictures"
"""The folder of the release's ``docs/`` that the pages' pictures go to."""

_TOCTREE = re.compile(r"^```\{toctree\}.*?^```\n?", re.M | re.S)
COURSE_ONLY = re.compile(r"^<!-- course only -->\n.*?^<!-- end course only -->\n?", re.M | re.S)
"""A part of a student page about a clone of the course, left out of the release."""
_ROLE = re.compile(r"\{[a-z]+(?::[a-z]+)*\}(`[^`]+`)")
_LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")


def write(course: Path, release: Path) -> list[Path]:
    """Write the student pages of ``course`` into ``release``/docs (after the rest of the
    release is written: a link is kept where its target is in it); return the files (none
    where the course has no student pages)."""
    pages = sorted((Path(course) / PAGES).glob("*.md"))
    if not pages:  # a course without the documentation
        return []
    out = Path(release) / TARGET
    out.mkdir(parents=True, exist_ok=True)
    names = {page.name for page in pages}
    written = []
    for page in pages:
        text = _TOCTREE.sub("", COURSE_ONLY.sub("", page.read_text(encoding="utf-8")))
        text = _ROLE.sub(r"\1", text)
        text = _LINK.sub(partial(_link, page=page, out=out, names=names, written=written), text)
        target = out / page.name
        target.write_text(text, encoding="utf-8")
        written.append(target)
    return written


def _link(match: re.Match[str], page: Path, out: Path, names: set[str], written: list) -> str:
    """One Markdown link or picture of ``page``, as the release's copy shows it."""
    picture, text, target = match[1], match[2], match[3]
    path = target.partition("#")[0]
    if re.match(r"[a-z]+:", target) or not path or path in names:
        return match[0]  # a web address, an anchor of the page, another student page
    source = (page.parent / path).resolve()
    if picture and source.is_file():
        copy = out / PICTURES / source.name
        copy.parent.mkdir(exist_ok=True)
        shutil.copyfile(source, copy)
        written.append(copy)
        return f"![{text}]({PICTURES}/{source.name})"
    if (out / path).resolve().is_file():
        return match[0]  # e.g. ../notebooks/task1.ipynb: the release's notebooks
    return text if not picture else ""
