"""Every table of the docs names each column in its header: a screen reader reads an empty
header cell as nothing (axe-core's rule empty-table-header)."""

import re
from itertools import pairwise
from pathlib import Path

DOCS = Path(__file__).resolve().parents[2] / "docs"
SEPARATOR = re.compile(r"^\|(\s*:?-+:?\s*\|)+\s*$")


def header_rows(text: str) -> list[str]:
    """The header rows of the Markdown tables in ``text``: each row followed by |---|."""
    lines = text.splitlines()
    return [line for line, below in pairwise(lines) if SEPARATOR.match(below)]


def test_no_table_of_the_docs_has_an_empty_header_cell():
    empty = [
        f"{path.relative_to(DOCS)}: {row}"
        for path in DOCS.rglob("*.md")
        if "_build" not in path.parts
        for row in header_rows(path.read_text(encoding="utf-8"))
        if any(not cell.strip() for cell in row.strip().strip("|").split("|"))
    ]
    assert not empty, "\n".join(empty)
