"""A standalone HTML page for the instructor's reports: one file, its style inline."""

from __future__ import annotations

import html
from collections.abc import Iterable
from pathlib import Path

from . import output_files


def write_page(path: Path, title: str, style: str, parts: Iterable[str]) -> None:
    """Write ``parts`` (HTML fragments; empty ones left out) as one UTF-8 page, all of
    them in its main landmark (where a screen reader's "main" goes)."""
    page = (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{html.escape(title)}</title><style>{style}</style></head><body><main>\n"
        + "\n".join(part for part in parts if part)
        + "\n</main></body></html>\n"
    )
    output_files.write_text(path, page, "page")
