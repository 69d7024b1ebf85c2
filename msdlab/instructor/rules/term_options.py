"""The ``msdlab grade`` options on due dates and late work, and the run's `Terms` from them
and the instructor's files, checked whole."""

from __future__ import annotations

import argparse
import difflib
import sys
import tempfile
from collections.abc import Collection, Mapping
from datetime import datetime, timezone
from fractions import Fraction
from pathlib import Path

from ...course import TASKS, manifest
from .. import intake, release
from . import adjustments, final_points, late
from .final_points import Terms
from .problems import InstructorFileError, Problem


def register(parser: argparse.ArgumentParser) -> None:
    """Add --due, --late-policy, --timezone, --extensions and --handed-in to ``parser``."""
    parser.add_argument(
        "--due", metavar="DATE", help="due date and time, e.g. 2027-03-01T23:59 (see --timezone)"
    )
    parser.add_argument(
        "--late-policy",
        default="",
        metavar="POLICY",
        help=f"what late work costs, e.g. {late.EXAMPLE.replace('%', '%%')} (default: nothing)",
    )
    parser.add_argument(
        "--timezone",
        metavar="ZONE",
        help="time zone of a due date without offset, e.g. Europe/Berlin (default: this machine's)",
    )
    parser.add_argument(
        "--extensions", type=Path, metavar="CSV", help="own due dates: 'id,extension' or 'id,due'"
    )
    parser.add_argument(
        "--handed-in",
        choices=intake.SOURCES,
        default="auto",
        help="where the hand-in time is read (default: auto)",
    )
    parser.add_argument(
        "--unverified-time",
        choices=intake.UNVERIFIED_POLICIES,
        default="flag",
        help="what a hand-in time the student could have set (a commit date, zip or file "
        "time) or that could not be read gets: flag (default: taken as read, marked in the "
        "row, the feedback and the summary), accept (taken as read), late (charged as "
        "handed in when this run took it in)",
    )


def terms(args: argparse.Namespace) -> tuple[Terms, list[Problem]]:
    """The run's due dates, late policy and manual changes, and every mistake in the options
    and files they come from that shows without the class (`adjustments.against_class`
    checks the rest). An unknown --timezone stops here."""
    found: list[Problem] = []
    zone = late.time_zone(args.timezone)
    policy = late.LatePolicy()
    try:
        policy = late.LatePolicy.parse(args.late_policy)
    except InstructorFileError as error:
        found += error.problems
    due, own = None, {}
    if args.due is None and (args.late_policy or args.extensions):
        found.append(Problem("command line", "--late-policy and --extensions need --due DATE"))
    elif args.due is not None:
        try:
            due = late.parse_due(args.due, zone)
        except ValueError as error:
            found.append(Problem("command line", str(error)))
        if args.extensions:  # its mistakes are named even when --due is wrong (then refused)
            stand_in = due or datetime.now(timezone.utc)
            own, wrong = late.read_extensions(args.extensions, stand_in, zone)
            found += wrong
    path = adjustments.beside(args.out)
    changes, wrong = adjustments.parse(path)
    found += wrong + adjustments.problems(changes, str(path))
    return Terms(due, policy, own, changes=adjustments.by_student(changes)), found


def extensions_against_class(
    args: argparse.Namespace, terms: Terms, known: Collection[str]
) -> list[Problem]:
    """The --extensions file's ids that no submission has: a lookalike of one (case,
    spaces) is refused, any other warned about (a typo, or a student not taken in yet)."""
    found = []
    for identifier in sorted(set(terms.own_due) - set(known)):
        alike = sorted(
            k for k in known if adjustments.plain_id(k) == adjustments.plain_id(identifier)
        )
        near = difflib.get_close_matches(identifier, sorted(known), n=1)
        hint = f" (did you mean {near[0]!r}?)" if near else ""
        problem = Problem(str(args.extensions), f"no submission has the id {identifier!r}",
                          f"did you mean {alike[0]!r}? write the id exactly" if alike else
                          f"its extension waits for one; check the id against the roster{hint}",
                          refused=bool(alike))  # fmt: skip
        found.append(problem)
    return found


def possible_points(maximum: Mapping[str, str], checks: Path) -> dict[str, Fraction]:
    """What each task (``task1`` ...) and the ``total`` are worth: the grades' row of maximum
    points ``maximum`` where a run wrote it, else from collecting the ``checks``."""
    written = final_points.worth(maximum)
    if written is not None:
        return written
    with tempfile.TemporaryDirectory(prefix="msdlab-points-") as scratch:
        path = Path(scratch) / manifest.FILE_NAME
        release.write_points(checks, path)
        worth = manifest.worth(path)
    points = {f"task{task}": Fraction(worth.get(task, 0)) for task in TASKS}
    return {**points, "total": sum(points.values(), Fraction(0))}


def rules(args: argparse.Namespace, terms: Terms) -> intake.Rules:
    """How the intake reads and takes each submission's hand-in time in this run."""
    return intake.Rules(
        source=args.handed_in,
        zone=late.time_zone(args.timezone),
        due_of=terms.due_of if terms.due is not None else (lambda identifier: None),
        cutoff=terms.policy.cutoff,
        unverified=args.unverified_time,
    )


def unverified(entries: list[intake.Entry]) -> str | None:
    """The console's line counting the hand-in times not verified (None: every one was)."""
    flagged = [e.id for e in entries if e.handed_in is not None and not e.handed_in.verified]
    if not flagged:
        return None
    shown = ", ".join(flagged[:8]) + (", ..." if len(flagged) > 8 else "")
    return (f"hand-in time not verified for {len(flagged)} of {len(entries)} submissions "
            f"(set by the student's machine, or unreadable): {shown}")  # fmt: skip


def report(terms: Terms, grades_file: Path) -> None:
    """Say on stderr how many manual changes apply."""
    count = sum(len(changes) for changes in terms.changes.values())
    if count:
        print(f"manual changes: {count} from {adjustments.beside(grades_file)}", file=sys.stderr)
