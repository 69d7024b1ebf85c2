"""The grader's temporary folders, named in what a student or an instructor reads only by the
file's name: a path under ``msdlab-grade-…``, ``msdlab-intake-…``, ``msdlab-sandbox-…`` or
``msdlab-check-…`` says nothing to them and changes from run to run."""

from __future__ import annotations

import re

_TEMPORARY = re.compile(
    r"[^\s'\"()]*msdlab-(?:grade|intake|sandbox|check)-[^/\s'\"()]*((?:/[^/\s'\"():,;]+)*)"
)


def scrub(text: str) -> str:
    """``text`` without the grader's temporary paths: a file there is named by its name."""

    def name(match: re.Match) -> str:
        rest = match.group(1).rstrip(".")
        return rest.rsplit("/", 1)[-1] if rest and rest != "/submission" else "the submission"

    return _TEMPORARY.sub(name, text)
