"""The ``msdlab grade`` options on due dates and late work, and the run's `Terms` from them."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import adjustments, handin, late
from .final_points import Terms
from .intake import Entry


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
        choices=handin.SOURCES,
        default="auto",
        help="where the hand-in time is read (default: auto)",
    )


def terms(args: argparse.Namespace) -> Terms:
    """The run's due dates, late policy and manual changes, with clear errors for bad ones."""
    zone = late.time_zone(args.timezone)
    policy = late.LatePolicy.parse(args.late_policy)
    if args.due is None:
        if args.late_policy or args.extensions:
            raise ValueError("--late-policy and --extensions need --due DATE")
        return Terms(policy=policy, changes=adjustments.read(adjustments.beside(args.out)))
    due = late.parse_due(args.due, zone)
    own = late.read_extensions(args.extensions, due, zone) if args.extensions else {}
    changes = adjustments.read(adjustments.beside(args.out))
    return Terms(due=due, policy=policy, own_due=own, changes=changes)


def read_hand_ins(
    entries: dict[str, Entry], source: str, terms: Terms, timezone: str | None, scratch: Path
) -> None:
    """Each entry's hand-in time into ``terms``; an entry graded from a commit's files
    gets that folder; a hand-in time that could not be read is noted where it matters."""
    zone = late.time_zone(timezone)
    for identifier, entry in entries.items():
        if entry.problem is not None:
            continue
        due = terms.due_of(identifier)
        cutoff = due + terms.policy.cutoff if due and terms.policy.cutoff is not None else None
        handed = handin.handed_in(entry, source, zone, cutoff, scratch / str(len(terms.handed_in)))
        terms.handed_in[identifier] = handed
        if handed.folder is not None:
            entry.folder = handed.folder
        if handed.note and (due is not None or handed.time is not None):
            entry.notes.append(handed.note)


def report(terms: Terms, known: set[str], grades_file: Path) -> None:
    """Say on stderr which changes apply, and which name a student the grades do not have."""
    count = sum(len(changes) for changes in terms.changes.values())
    if count:
        print(f"manual changes: {count} from {adjustments.beside(grades_file)}", file=sys.stderr)
    for identifier in sorted(set(terms.changes) - known):
        print(
            f"warning: {adjustments.beside(grades_file)} changes {identifier!r}, who has no row "
            f"in {grades_file}",
            file=sys.stderr,
        )
    for identifier in sorted(set(terms.own_due) - known):
        print(f"warning: the extensions name {identifier!r}, who has no row", file=sys.stderr)
