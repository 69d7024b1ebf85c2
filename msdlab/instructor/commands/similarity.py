"""``msdlab similarity SUBMISSION... --out DIR``: which pairs of students share code.

Each SUBMISSION is given as to ``msdlab grade`` (a folder laid out like
assignments/, a folder holding assignments/, a zip file of either, or --roster
FILE). Only the task files the grader grades are read (regular files, no link, at
most 1 MB). Every pair of students is compared over all their task files with the
template's text (--template, default the course's assignments/) left out; variable
names, comments and the order of functions do not hide a copy. Prints the ten most
similar pairs; writes DIR/similarity.html (the most similar pairs with their matching
passages side by side, the others in a table) and DIR/similarity.csv (first, second,
similarity, first_share, second_share, matched, flagged, task1.py ... task5.py). It
flags pairs to look at; it changes no points. Needs msdlab[grade] (copydetect)."""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ...course import PROJECT_ROOT
from .. import intake

if TYPE_CHECKING:  # copydetect, which similarity imports, is optional
    from ..outputs.similarity import Pair

TEMPLATES = PROJECT_ROOT / "assignments"
THRESHOLD = 0.5  # similarity from which a pair is flagged, by default
PRINTED = 10  # pairs printed, most similar first (the page and the CSV have them all)


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "similarity",
        help="rank pairs of students by the code their task files share (instructors)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("submissions", nargs="*", type=Path, metavar="SUBMISSION")
    parser.add_argument(
        "--roster",
        type=Path,
        default=None,
        help="the class: a CSV whose first line names its columns, 'id' and 'folder'",
    )
    parser.add_argument(
        "--out", type=Path, default=Path("similarity"), help="folder for the report (%(default)s)"
    )
    parser.add_argument(
        "--template",
        type=Path,
        default=TEMPLATES,
        help="folder of the student templates whose text is left out (the course's assignments/)",
    )
    parser.add_argument(
        "--threshold",
        type=float,
        default=THRESHOLD,
        help="similarity (0 to 1) from which a pair is flagged (%(default)s)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if not args.roster and not args.submissions:
        raise ValueError("give SUBMISSION folders or zip files, or --roster FILE")
    with intake.taken_in(args.submissions, args.roster) as found:
        for line in found.refused + [
            f"not compared: {e.id}: {e.problem}" for e in found.entries if e.problem
        ]:
            print(line, file=sys.stderr)
        folders = {e.id: e.folder for e in found.entries if e.problem is None}
        write_report(folders, args.out, args.template, args.threshold, left_out_at(found))
    return 0


def require_copydetect() -> None:
    """A clear error where copydetect, an optional dependency, is not installed."""
    if importlib.util.find_spec("copydetect") is None:
        raise RuntimeError(
            "the similarity report needs copydetect: pip install 'msdlab[grade]' "
            "(or pip install copydetect)"
        )


def left_out_at(found: intake.Intake) -> list[str]:
    """What the intake left out of the submissions it took in ('ID: NOTE'), for the report."""
    return [f"{e.id}: {note}" for e in found.entries if e.problem is None
            for note in e.notes if intake.LEFT_OUT in note]  # fmt: skip


def write_report(
    folders: dict[str, Path],
    out: Path,
    template: Path = TEMPLATES,
    threshold: float = THRESHOLD,
    left_out_before: list[str] | None = None,
) -> None:
    """Compare the submissions in ``folders`` (id -> folder); write out/similarity.html and
    out/similarity.csv and print the most similar pairs. ``left_out_before``: what the
    intake left out of them (`left_out_at`)."""
    require_copydetect()
    if not 0.0 < threshold <= 1.0:
        raise ValueError(f"--threshold is a similarity between 0 and 1, got {threshold}")
    if not template.is_dir():
        raise FileNotFoundError(f"no template folder at {template}; give --template DIR")
    from ..outputs import similarity, similarity_report

    texts, left_out = {}, list(left_out_before or [])
    for student, folder in folders.items():
        texts[student], problems = similarity.task_texts(folder)
        left_out += [f"{student}: {problem}" for problem in problems]
    pairs = similarity.compare(texts, template)
    out.mkdir(parents=True, exist_ok=True)
    similarity.write_csv(pairs, out / "similarity.csv", threshold)
    similarity_report.write_html(pairs, out / "similarity.html", len(folders), threshold, left_out)
    print(ranked_list(pairs, threshold))
    for line in left_out[:PRINTED]:
        print(f"  not compared: {line}")
    if len(left_out) > PRINTED:
        print(f"  ... {len(left_out) - PRINTED} more files not compared (the page lists them)")
    print(f"report written to {out / 'similarity.html'} and {out / 'similarity.csv'}")


def ranked_list(pairs: list[Pair], threshold: float) -> str:
    """The lines to print: how many pairs are flagged, and the `PRINTED` most similar."""
    flagged = sum(pair.flagged(threshold) for pair in pairs)
    lines = [
        f"{flagged} of {len(pairs)} pairs of students flagged (similarity >= {threshold}, "
        "over all task files or in one)"
    ]
    top = [pair for pair in pairs[:PRINTED] if max(pair.matched) > 0]
    width = max((len(" and ".join(p.students)) for p in top), default=0)
    for rank, pair in enumerate(top, 1):
        files = ", ".join(f"{f.task_file[:-3]} {f.similarity:.2f}" for f in pair.files)
        mark = "flagged" if pair.flagged(threshold) else "       "
        lines.append(f"{rank:>3}. {' and '.join(pair.students):<{width}}  "
                     f"{pair.similarity:.2f}  {mark}  ({files})")  # fmt: skip
    return "\n".join(lines)
