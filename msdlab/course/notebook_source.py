"""A course notebook's source, ``notebooks/src/NAME.py``, and the cells it makes.

A source is a Python file in the percent format: ``# %%`` starts a code cell,
``# %% [markdown]`` a Markdown cell whose lines are comments (``# text``). The numbers a
student reads are markers ``{{ name }}``, filled in from the course's or the student's own
numbers (`own_numbers.filled`). ``notebooks/build.py`` makes the course's notebooks from
the sources, ``msdlab release`` a student's (with their own numbers).
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path
from typing import Any

from . import own_numbers

MARKER = re.compile(r"# %%(?P<markdown> \[markdown\])?\s*$")


def notebook_cells(
    source: Path, own: own_numbers.Numbers = own_numbers.DEFAULT
) -> list[dict[str, Any]]:
    """The cells of the notebook source file ``source`` with the numbers ``own``."""
    text = source.read_text(encoding="utf-8")
    return cells(own_numbers.filled(text, own, source.name), source.name)


def cells(text: str, name: str = "the notebook's source") -> list[dict[str, Any]]:
    """The cells (notebook JSON, format 4) of a source's ``text``, each with an id made from
    its content."""
    chunks: list[tuple[bool, list[str]]] = []
    for number, line in enumerate(text.splitlines(), 1):
        marker = MARKER.match(line)
        if marker:
            chunks.append((bool(marker["markdown"]), []))
        elif chunks:
            chunks[-1][1].append(line)
        elif line.strip():
            raise ValueError(f"{name}:{number}: text before the first '# %%' cell marker")
    made: list[dict[str, Any]] = []
    seen: set[str] = set()
    for markdown, lines in chunks:
        body = "\n".join(_markdown(lines, name) if markdown else lines).strip("\n")
        if not body.strip():
            continue
        digest = hashlib.sha1(body.encode()).hexdigest()[:8]
        cell_id = digest if digest not in seen else f"{digest}-{len(made)}"
        seen.add(cell_id)
        cell = {"cell_type": "markdown" if markdown else "code", "id": cell_id, "metadata": {}}
        if not markdown:
            cell.update(execution_count=None, outputs=[])
        made.append({**cell, "source": body})
    return made


def _markdown(lines: list[str], name: str) -> list[str]:
    """Comment lines ``# text`` -> ``text``."""
    for line in lines:
        if line.strip() and not line.startswith("#"):
            raise ValueError(
                f"{name}: a Markdown cell holds a line that is not a comment: {line!r}"
            )
    return [line[2:] if line.startswith("# ") else line[1:] for line in lines]
