"""The similarity report as one HTML page of bounded size: the most similar pairs of students
in full, their matching passages side by side, each passage coloured like its twin and linked
to it; every other pair that shares code as one row of a table.

The page holds at most `IN_FULL` pairs in full, `TABLE_ROWS` rows, and `SHOWN_CHARACTERS` of
each file shown, so its size does not grow with the square of the class.
"""

from __future__ import annotations

import bisect
import html
import itertools
from pathlib import Path

from .html_page import write_page
from .similarity import MIN_MATCHED, NOISE, TASK_FILES, FileMatch, Pair, Passage

IN_FULL = 10
"""The most similar pairs shown with their passages side by side."""
TABLE_ROWS = 300
"""Rows of the table of pairs (the CSV has every pair)."""
SHOWN_CHARACTERS = 20_000
"""Characters of each file shown (a task file of the course is a few thousand)."""
CONTEXT = 3
"""Lines shown before and after a matching passage; the others are folded."""
COLOURS = 12
"""Distinct colours of matching passages; the 13th group takes the first colour again."""

STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }
td.number { text-align: right; font-variant-numeric: tabular-nums; }
tr.flagged { background: #fde2e2; }
.sides { display: grid; grid-template-columns: 1fr 1fr; gap: 1em; }
.sides pre { border: 1px solid #ccc; padding: 0.5em; overflow-x: auto; font-size: 0.8em;
             line-height: 1.4; margin: 0; }
a.passage { color: inherit; text-decoration: underline dotted; border-radius: 2px; }
a.passage:target { outline: 3px solid #222; }
.folded { color: #595959; font-style: italic; }
h2 { margin-top: 2em; }
"""
PALETTE = ("#f6c343", "#8fd3f4", "#b5e48c", "#f4a6c6", "#c7a6f4", "#f9a66c",
           "#7fe0c4", "#e0e07f", "#a6b8f4", "#f47f7f", "#c4c4c4", "#d9b38c")  # fmt: skip


def write_html(
    pairs: list[Pair], path: Path, submissions: int, threshold: float, left_out: list[str]
) -> None:
    """Write the report of ``pairs`` (most similar first) to ``path``; ``left_out`` names
    the files not compared and why."""
    sharing = [pair for pair in pairs if max(pair.matched) > 0]
    flagged = sum(pair.flagged(threshold) for pair in pairs)
    in_full = sharing[:IN_FULL]
    body = [
        "<h1>Similarity of the students' task files</h1>",
        f"<p>{submissions} submissions, {len(pairs)} pairs of students compared over "
        f"{len(TASK_FILES)} task files, <strong>{flagged} flagged</strong> (similarity at "
        f"least {threshold:.2f}, over all task files or in one, and at least {MIN_MATCHED} "
        "characters of matching code). The template's text is left out; names of variables, "
        "functions and objects do not count, nor do comments. A student's share is the part "
        "of their own code, over all task files, found in the other's files of the same "
        "tasks; the pair's similarity is the larger share. The report flags pairs to look "
        "at: it changes no points.</p>",
        _table(sharing[:TABLE_ROWS], threshold, len(in_full)),
        _not_listed(len(pairs), len(sharing)),
        _left_out(left_out),
        *(_in_full(number, pair, threshold) for number, pair in enumerate(in_full, 1)),
    ]
    write_page(path, "Similarity report", STYLE + _colour_rules(), body)


def _colour_rules() -> str:
    return "".join(f".g{i} {{ background: {c}; }}\n" for i, c in enumerate(PALETTE))


def _not_listed(compared: int, sharing: int) -> str:
    lines = []
    if sharing > TABLE_ROWS:
        lines.append(f"{sharing - TABLE_ROWS} more pairs share less; similarity.csv lists them.")
    if compared > sharing:
        lines.append(
            f"{compared - sharing} pairs share no passage of {NOISE} characters or more of "
            "code and are not listed."
        )
    return f"<p>{' '.join(lines)}</p>" if lines else ""


def _left_out(left_out: list[str]) -> str:
    if not left_out:
        return ""
    shown = "".join(f"<li>{html.escape(line)}</li>" for line in left_out[:TABLE_ROWS])
    more = f"<li>… {len(left_out) - TABLE_ROWS} more</li>" if len(left_out) > TABLE_ROWS else ""
    heading = "<p>Files not compared (the grader does not grade them either):</p>"
    return f"{heading}<ul>{shown}{more}</ul>"


def _table(pairs: list[Pair], threshold: float, in_full: int) -> str:
    files = "".join(f"<th>{name}</th>" for name in TASK_FILES)
    head = (
        "<tr><th>rank</th><th>first</th><th>second</th><th>similarity</th>"
        f"<th>first's share</th><th>second's share</th><th>matching code (characters)</th>"
        f"{files}<th>flagged</th></tr>"
    )
    rows = []
    for number, pair in enumerate(pairs, 1):
        flagged = pair.flagged(threshold)
        rank = f'<a href="#pair-{number}">{number}</a>' if number <= in_full else str(number)
        per_file = (pair.file(name) for name in TASK_FILES)
        cells = [
            f'<td class="number">{rank}</td>',
            *(f"<td>{html.escape(student)}</td>" for student in pair.students),
            f'<td class="number">{pair.similarity:.2f}</td>',
            *(f'<td class="number">{share:.2f}</td>' for share in pair.shares),
            f'<td class="number">{max(pair.matched)}</td>',
            *(f'<td class="number">{_file_similarity(f)}</td>' for f in per_file),
            f"<td>{'yes' if flagged else 'no'}</td>",
        ]
        rows.append(f'<tr class="{"flagged" if flagged else ""}">{"".join(cells)}</tr>')
    return f"<table>{head}{''.join(rows)}</table>"


def _file_similarity(match: FileMatch | None) -> str:
    return "" if match is None else f"{match.similarity:.2f}"


def _in_full(number: int, pair: Pair, threshold: float) -> str:
    first, second = (html.escape(s) for s in pair.students)
    verdict = "flagged" if pair.flagged(threshold) else "not flagged"
    files = [_sides(f"p{number}-{f.task_file[:-3]}", f, pair.students) for f in pair.files]
    return (
        f'<h2 id="pair-{number}">{number}. {first} and {second}: similarity '
        f"{pair.similarity:.2f} ({verdict})</h2>" + "".join(f for f in files if f)
    )


def _sides(anchor: str, match: FileMatch, students: tuple[str, str]) -> str:
    """Both files of one task side by side, or nothing where they share no passage."""
    if not any(match.matched):
        return ""
    columns = []
    for side, (student, text, passages) in enumerate(zip(students, match.texts, match.passages)):
        share = match.matched[side] / match.code[side] if match.code[side] else 0.0
        columns.append(
            f"<div><h4>{html.escape(student)}: {match.task_file} ({share:.0%} of its own code "
            f"matches)</h4><pre>{highlighted(text, passages, anchor, side)}</pre></div>"
        )
    return (
        f"<h3>{match.task_file}: similarity {match.similarity:.2f}</h3>"
        f'<div class="sides">{"".join(columns)}</div>'
    )


def highlighted(text: str, passages: tuple[Passage, ...], anchor: str, side: int) -> str:
    """``text`` (its first `SHOWN_CHARACTERS`) as HTML: each passage a link, coloured by its
    group, to the first passage of its group on the other side; lines farther than `CONTEXT`
    from any passage folded into one line saying how many. ``anchor`` makes ids unique."""
    shown = text[:SHOWN_CHARACTERS]
    marks, done = [], 0
    for passage in sorted(passages, key=lambda p: p.start):
        start, end = _whole_words(shown, passage.start, passage.end)
        start, end = max(start, done), min(end, len(shown))
        if end > start:
            marks.append((start, end, passage.group))
            done = end
    lines = shown.splitlines(keepends=True)
    starts = list(itertools.accumulate((len(line) for line in lines), initial=0))
    near = set()
    for start, end, _ in marks:
        first, last = bisect.bisect_right(starts, start) - 1, bisect.bisect_left(starts, end) - 1
        near.update(range(first - CONTEXT, last + CONTEXT + 1))
    parts, folded, named = [], 0, set()
    for number, line in enumerate(lines):
        if number not in near:
            folded += 1
            continue
        if folded:
            parts.append(_folded(folded))
            folded = 0
        parts.append(_line(line, starts[number], marks, anchor, side, named))
    if folded:
        parts.append(_folded(folded))
    if len(text) > len(shown):
        parts.append(f"… {len(text) - len(shown)} more characters not shown\n")
    return "".join(parts)


def _whole_words(text: str, start: int, end: int) -> tuple[int, int]:
    """[start, end) widened to whole words: copydetect places a match by characters of its
    reduced code, which may fall inside a name of the text."""
    while 0 < start < len(text) and (text[start - 1].isalnum() or text[start - 1] == "_"):
        start -= 1
    while 0 < end < len(text) and (text[end].isalnum() or text[end] == "_"):
        end += 1
    return start, end


def _folded(count: int) -> str:
    return f'<span class="folded">⋮ {count} line{"s" if count > 1 else ""} without a match</span>\n'


def _line(
    line: str, offset: int, marks: list[tuple[int, int, int]], anchor: str, side: int,
    named: set[int],
) -> str:  # fmt: skip
    """One line as HTML, the parts of passages in it as links; ``named`` holds the groups
    whose first passage on this side already has its id."""
    parts, done = [], 0
    for start, end, group in marks:
        start, end = max(start - offset, done), min(end - offset, len(line))
        if not line[start:end].strip():  # nothing to read as a link: left as it is
            continue
        here = (
            "" if group in named else f' id="{anchor}-{"ab"[side]}{group}" title="go to its twin"'
        )
        named.add(group)
        parts += [
            html.escape(line[done:start]),
            f'<a class="passage g{(group - 1) % COLOURS}"{here} href="#{anchor}-{"ba"[side]}'
            f'{group}">{html.escape(line[start:end])}</a>',
        ]
        done = end
    parts.append(html.escape(line[done:]))
    return "".join(parts)
