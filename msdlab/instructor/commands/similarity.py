"""``msdlab similarity SUBMISSION... --out DIR``: which students' task files share code.

Each SUBMISSION is given as to ``msdlab grade`` (a folder laid out like
assignments/, a folder holding assignments/, a zip file of either, or --roster
FILE). Every pair of students is compared per task file with the template's text
(--template, default the course's assignments/) left out; variable names,
comments and the order of functions do not hide a copy. Writes DIR/similarity.html
(pairs ranked, matching passages side by side) and DIR/similarity.csv (task_file,
first, second, similarity, first_share, second_share, matched, flagged). It flags
pairs to look at; it changes no points. Needs msdlab[grade] (copydetect).
"""

from __future__ import annotations

import argparse
import importlib.util
from pathlib import Path

from ...course import PROJECT_ROOT
from .. import intake

TEMPLATES = PROJECT_ROOT / "assignments"
THRESHOLD = 0.5  # similarity from which a pair is flagged, by default


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "similarity",
        help="rank pairs of students by the code their task files share (instructors)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("submissions", nargs="*", type=Path, metavar="SUBMISSION")
    parser.add_argument(
        "--roster", type=Path, default=None, help="CSV of 'id,folder-or-zip' rows instead"
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
    if bool(args.roster) == bool(args.submissions):
        raise ValueError("give SUBMISSION folders or zip files, or --roster FILE (not both)")
    with (
        intake.from_roster(args.roster)
        if args.roster
        else intake.from_paths(args.submissions) as found
    ):
        folders = {e.id: e.folder for e in found.entries if e.problem is None}
        write_report(folders, args.out, args.template, args.threshold)
    return 0


def require_copydetect() -> None:
    """A clear error where copydetect, an optional dependency, is not installed."""
    if importlib.util.find_spec("copydetect") is None:
        raise RuntimeError(
            "the similarity report needs copydetect: pip install 'msdlab[grade]' "
            "(or pip install copydetect)"
        )


def write_report(
    folders: dict[str, Path],
    out: Path,
    template: Path = TEMPLATES,
    threshold: float = THRESHOLD,
) -> None:
    """Compare the submissions in ``folders`` (id -> folder); write out/similarity.html and
    out/similarity.csv and print the flagged pairs."""
    require_copydetect()
    if not 0.0 < threshold <= 1.0:
        raise ValueError(f"--threshold is a similarity between 0 and 1, got {threshold}")
    if not template.is_dir():
        raise FileNotFoundError(f"no template folder at {template}; give --template DIR")
    from .. import similarity, similarity_report

    pairs = similarity.compare(folders, template)
    out.mkdir(parents=True, exist_ok=True)
    similarity.write_csv(pairs, out / "similarity.csv", threshold)
    similarity_report.write_html(pairs, out / "similarity.html", len(folders), threshold)
    flagged = [pair for pair in pairs if pair.flagged(threshold)]
    print(f"{len(flagged)} of {len(pairs)} pairs of task files flagged (similarity >= {threshold})")
    for pair in flagged:
        first, second = pair.students
        print(f"  {pair.task_file}  {first} and {second}  similarity {pair.similarity:.2f}")
    print(f"report written to {out / 'similarity.html'} and {out / 'similarity.csv'}")
