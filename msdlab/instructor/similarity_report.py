"""The similarity report as one HTML page: pairs ranked, matching passages side by side."""

from __future__ import annotations

import html
from pathlib import Path

from .similarity import MIN_MATCHED, NOISE, Pair

STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }
td.number { text-align: right; font-variant-numeric: tabular-nums; }
tr.flagged { background: #fde2e2; }
.sides { display: grid; grid-template-columns: 1fr 1fr; gap: 1em; }
.sides pre { border: 1px solid #ccc; padding: 0.5em; overflow-x: auto; font-size: 0.8em;
             margin: 0; }
mark { background: #f6c343; }
h2 { margin-top: 2em; }
"""


def write_html(pairs: list[Pair], path: Path, submissions: int, threshold: float) -> None:
    """Write the report of ``pairs`` (most similar first) to ``path``."""
    shown = [pair for pair in pairs if pair.matched > 0]
    flagged = sum(pair.flagged(threshold) for pair in pairs)
    body = [
        "<h1>Similarity of the students' task files</h1>",
        f"<p>{submissions} submissions, {len(pairs)} pairs of task files compared, "
        f"<strong>{flagged} flagged</strong> (similarity at least {threshold:.2f} and at least "
        f"{MIN_MATCHED} characters of matching code). The template's text is left out; names "
        "of variables, functions and objects do not count, nor do comments. A pair's share "
        "of a file is the part of that file's own code found in the other; its similarity is "
        "the larger share. The report flags pairs to look at: it changes no points.</p>",
        _table(shown, threshold),
    ]
    if len(shown) < len(pairs):
        body.append(
            f"<p>{len(pairs) - len(shown)} pairs share no passage of {NOISE} characters "
            "or more of code and are not listed.</p>"
        )
    body += [_sides(number, pair, threshold) for number, pair in enumerate(shown, 1)]
    page = (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>Similarity report</title><style>{STYLE}</style></head><body>\n"
        + "\n".join(body)
        + "\n</body></html>\n"
    )
    path.write_text(page, encoding="utf-8")


def _table(pairs: list[Pair], threshold: float) -> str:
    head = (
        "<tr><th>rank</th><th>task file</th><th>first</th><th>second</th><th>similarity</th>"
        "<th>first's share</th><th>second's share</th><th>matching code (characters)</th>"
        "<th>flagged</th></tr>"
    )
    rows = []
    for number, pair in enumerate(pairs, 1):
        flagged = pair.flagged(threshold)
        first, second = (html.escape(s) for s in pair.students)
        cells = [
            f'<td class="number"><a href="#pair-{number}">{number}</a></td>',
            f"<td>{pair.task_file}</td><td>{first}</td><td>{second}</td>",
            f'<td class="number">{pair.similarity:.2f}</td>',
            *(f'<td class="number">{share:.2f}</td>' for share in pair.shares),
            f'<td class="number">{pair.matched}</td>',
            f"<td>{'yes' if flagged else 'no'}</td>",
        ]
        rows.append(f'<tr class="{"flagged" if flagged else ""}">{"".join(cells)}</tr>')
    return f"<table>{head}{''.join(rows)}</table>"


def _sides(number: int, pair: Pair, threshold: float) -> str:
    first, second = (html.escape(s) for s in pair.students)
    verdict = "flagged" if pair.flagged(threshold) else "not flagged"
    columns = "".join(
        f"<div><h3>{html.escape(student)}: {pair.task_file} ({share:.0%} of it matches)</h3>"
        f"<pre>{highlighted(text, passages)}</pre></div>"
        for student, share, text, passages in zip(
            pair.students, pair.shares, pair.texts, pair.passages
        )
    )
    return (
        f'<h2 id="pair-{number}">{number}. {pair.task_file}: {first} and {second}, '
        f"similarity {pair.similarity:.2f} ({verdict})</h2>"
        f'<div class="sides">{columns}</div>'
    )


def highlighted(text: str, passages: tuple[tuple[int, int], ...]) -> str:
    """``text`` as HTML with each (start, end) character range in <mark>."""
    parts, done = [], 0
    for start, end in sorted(passages):
        start = max(start, done)
        if end <= start:
            continue
        parts += [html.escape(text[done:start]), f"<mark>{html.escape(text[start:end])}</mark>"]
        done = end
    parts.append(html.escape(text[done:]))
    return "".join(parts)
