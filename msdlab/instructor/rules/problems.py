"""Mistakes in the instructor's files and options, each with where it is, what is wrong and
the fix: refused (nothing is graded or exported until it is fixed) or, where the intent is
clear, a warning.

The checks of each file are pure functions from what was read to a list of `Problem`; the
commands gather every file's problems before they start, so one run names them all.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True)
class Problem:
    """One mistake: ``where`` (``grades.adjustments.csv, line 3``, ``--late-policy``), ``what``
    is wrong, the ``fix`` (where ``what`` does not say it); ``refused`` False for a warning."""

    where: str
    what: str
    fix: str = ""
    refused: bool = True

    def __str__(self) -> str:
        return f"{self.where}: {self.what}" + (f"; {self.fix}" if self.fix else "")


class InstructorFileError(ValueError):
    """The instructor's files or options hold mistakes that stop the run (all of them named)."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = sorted(problems, key=_place)
        count = f"{len(problems)} mistake{'s' * (len(problems) != 1)}"
        lines = "\n".join(f"  {problem}" for problem in self.problems)
        super().__init__(f"{count} in the instructor's files; fix and run again:\n{lines}")


def settle(problems: Iterable[Problem]) -> None:
    """Print the warnings among ``problems`` on stderr; raise `InstructorFileError` naming
    every refused one."""
    problems = list(problems)
    for problem in problems:
        if not problem.refused:
            print(f"warning: {problem}", file=sys.stderr)
    refused = [problem for problem in problems if problem.refused]
    if refused:
        raise InstructorFileError(refused)


def raise_refused(problems: Iterable[Problem]) -> None:
    """Raise `InstructorFileError` if any of ``problems`` is refused (warnings are left to
    the caller, who gathers them with the other files')."""
    refused = [problem for problem in problems if problem.refused]
    if refused:
        raise InstructorFileError(refused)


def _place(problem: Problem) -> tuple[str, int]:
    """Where ``problem`` is, in order: its file (or option), then its line."""
    where, _, line = problem.where.rpartition(", line ")
    return (where, int(line)) if where and line.isdigit() else (problem.where, 0)
