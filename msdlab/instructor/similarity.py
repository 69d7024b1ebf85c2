"""How much of each pair of students' task files is the same code, the template left out.

Each task file is reduced by copydetect (winnowing of fingerprints of its tokens,
with variable, function and object names replaced by one letter each and comments
left out), the fingerprints of the template's text are removed, and every pair of
students is compared per task file. A pair's share of a file is the part of that
file's own code (in characters of the reduced code) found in the other file; its
similarity is the larger of the two shares. Measured on the course's own tasks: a
copy with renamed variables scored 1.00, one with its functions reordered 0.86 to
0.95, independent honest solutions 0.00 to 0.23. The report flags; it changes no
points.
"""

from __future__ import annotations

import csv
import io
import itertools
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from copydetect import CodeFingerprint, compare_files

from ..course import TASKS

NOISE = 25
"""Shortest run of reduced code (characters) that counts as a match (copydetect's noise_t)."""
MIN_MATCHED = 100
"""A pair is flagged only if at least this much reduced code (characters) matches: two
honest one-line answers to the same question may well be the same."""


@dataclass(frozen=True)
class Pair:
    """Two students' versions of one task file and the code they share."""

    task_file: str
    students: tuple[str, str]
    shares: tuple[float, float]  # part of each one's own code found in the other's (0 .. 1)
    matched: int  # characters of reduced code that match
    texts: tuple[str, str]  # the two files as handed in
    passages: tuple[tuple[tuple[int, int], ...], tuple[tuple[int, int], ...]]  # (start, end)

    @property
    def similarity(self) -> float:
        """The larger share: a copy that added code of its own is still found in the other."""
        return max(self.shares)

    def flagged(self, threshold: float) -> bool:
        """Whether the pair is worth a look: similar enough, and more than a line or two."""
        return self.similarity >= threshold and self.matched >= MIN_MATCHED


def compare(submissions: Mapping[str, Path], templates: Path) -> list[Pair]:
    """Every pair of ``submissions`` (id -> folder of task files), per task file, the
    template's text in ``templates`` left out; most similar first."""
    pairs = []
    for task_file in (f"task{task}.py" for task in TASKS):
        template = _template_hashes(templates / task_file)
        prints = {
            student: _fingerprint(folder / task_file, template)
            for student, folder in sorted(submissions.items())
            if (folder / task_file).is_file()
        }
        for first, second in itertools.combinations(prints, 2):
            pairs.append(_pair(task_file, (first, second), prints[first], prints[second]))
    return sorted(pairs, key=lambda p: (-p.similarity, -p.matched, p.task_file, p.students))


def _template_hashes(template: Path) -> list[int]:
    if not template.is_file():  # without it the given code would count as shared
        raise FileNotFoundError(f"no template {template.name} in {template.parent}")
    return list(CodeFingerprint(str(template), NOISE, 1, fp=io.StringIO(_read(template))).hashes)


def _fingerprint(path: Path, template_hashes: list[int]) -> CodeFingerprint:
    # A window of 1 keeps every fingerprint: copydetect's winnowing picks by Python's hash(),
    # which differs from run to run, and so would the scores; every match >= NOISE is found.
    return CodeFingerprint(str(path), NOISE, 1, template_hashes, fp=io.StringIO(_read(path)))


def _read(path: Path) -> str:
    return path.read_text(encoding="utf-8", errors="replace")


def _pair(
    task_file: str, students: tuple[str, str], first: CodeFingerprint, second: CodeFingerprint
) -> Pair:
    matched, shares, slices = compare_files(first, second)
    passages = ((), ())  # without a match copydetect's slices are empty arrays of another shape
    if matched:
        passages = tuple(tuple(zip(map(int, cut[0]), map(int, cut[1]))) for cut in slices)
    return Pair(
        task_file,
        students,
        (float(shares[0]), float(shares[1])),
        int(matched),
        (first.raw_code, second.raw_code),
        passages,
    )


CSV_COLUMNS = ("task_file", "first", "second", "similarity", "first_share", "second_share",
               "matched", "flagged")  # fmt: skip


def write_csv(pairs: list[Pair], path: Path, threshold: float) -> None:
    """One row per pair and task file, most similar first (columns `CSV_COLUMNS`)."""
    with path.open("w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file)
        writer.writerow(CSV_COLUMNS)
        for pair in pairs:
            writer.writerow(
                [
                    pair.task_file,
                    *pair.students,
                    f"{pair.similarity:.2f}",
                    *(f"{share:.2f}" for share in pair.shares),
                    pair.matched,
                    "yes" if pair.flagged(threshold) else "no",
                ]
            )
