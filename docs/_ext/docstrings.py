"""Reads msdlab's docstrings, written as plain text for `help()`, as reStructuredText.

The docstrings use mathematical notation that reST would misread: ``|x_a - x_b|`` for a
norm (a substitution in reST), a formula after ``::`` at the paragraph's own indent, and
example code as a paragraph. This extension rewrites them for autodoc only; the source
keeps its plain-text form.
"""

from __future__ import annotations

import re

LITERAL = re.compile(r"(``.*?``)")


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def escape_bars(line: str) -> str:
    """``|`` as a literal bar, except inside ``inline literals``."""
    parts = LITERAL.split(line)
    return "".join(p if p.startswith("``") else p.replace("|", r"\|") for p in parts)


def as_rest(lines: list[str]) -> list[str]:
    """The docstring's lines with bars escaped, formulas after ``::`` indented and
    paragraphs of example code (starting with ``import``) made literal blocks."""
    out: list[str] = []
    literal_indent: int | None = None  # inside a literal block deeper than this
    after_colons: int | None = None  # a "::" paragraph ended at this indent
    index = 0
    while index < len(lines):
        line = lines[index]
        blank = not line.strip()
        if literal_indent is not None and not blank and _indent(line) <= literal_indent:
            literal_indent = None
        if after_colons is not None and not blank:
            if _indent(line) <= after_colons:  # a formula at the paragraph's indent
                while index < len(lines) and lines[index].strip():
                    out.append("    " + lines[index])
                    index += 1
                after_colons = None
                continue
            literal_indent, after_colons = after_colons, None
        if literal_indent is None and not blank and line.lstrip().startswith("import "):
            if out and out[-1].strip():
                out.append("")
            out += ["::", ""]
            while index < len(lines) and lines[index].strip():
                out.append("    " + lines[index])
                index += 1
            continue
        if literal_indent is None:
            line = escape_bars(line)
            if line.rstrip().endswith("::"):
                after_colons = _indent(line)
        out.append(line)
        index += 1
    return out


def process(app, what, name, obj, options, lines: list[str]) -> None:
    lines[:] = as_rest(lines)


def skip_foreign(app, what, name, obj, skip, options):
    """Leave out members a base class generates (matplotlib's ``Artist.set``)."""
    module = getattr(obj, "__module__", None) or ""
    if callable(obj) and module and not module.startswith("msdlab"):
        return True
    return None


def setup(app) -> dict[str, bool]:
    app.connect("autodoc-process-docstring", process)
    app.connect("autodoc-skip-member", skip_foreign)
    return {"parallel_read_safe": True}
