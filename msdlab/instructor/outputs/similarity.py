"""How much code each pair of students shares over all their task files, the template left out.

Each task file is reduced by copydetect (winnowing of fingerprints of its tokens,
with variable, function and object names replaced by one letter each and comments
left out), the fingerprints of the template's text are removed, and the two
students' files of the same task are compared. A student's **share** is the part
of all their own code (in characters of the reduced code, over every task file)
found in the other's files of the same tasks; the pair's **similarity** is the
larger of the two shares, and pairs are ranked by it. Each file's own similarity
is kept beside it, so a pair that copied one task only is still flagged. What was
measured on the course's tasks is in docs/instructor/similarity.md. The report
flags; it changes no points.

Only the files the grader grades are read (`task_texts`): ``task1.py`` ...
regular files, not links, of at most `MAX_FILE_BYTES`.
"""

from __future__ import annotations

import functools
import io
import itertools
import os
import stat
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from copydetect import CodeFingerprint, compare_files
from copydetect.utils import find_fingerprint_overlap, get_copied_slices

from ...course import TASKS
from ..judging.grading import MAX_FILE_BYTES
from . import csv_files

NOISE = 25
"""Shortest run of reduced code (characters) that counts as a match (copydetect's noise_t)."""
MIN_MATCHED = 100
"""A pair (or one of its files) is flagged only if at least this much reduced code
(characters) matches: two honest one-line answers to the same question may well be the same."""
TASK_FILES = tuple(f"task{task}.py" for task in TASKS)


@dataclass(frozen=True)
class Passage:
    """A matching run of one side's text, characters [start, end), and the number of its
    group: the passages of the other side it matches are in the same group."""

    start: int
    end: int
    group: int


@dataclass(frozen=True)
class FileMatch:
    """Two students' versions of one task file and the code they share."""

    task_file: str
    code: tuple[int, int]  # characters of each one's own reduced code (template left out)
    matched: tuple[int, int]  # of that, characters found in the other's file
    prints: tuple[CodeFingerprint, CodeFingerprint] = field(repr=False, compare=False)

    @property
    def texts(self) -> tuple[str, str]:
        """The two files as handed in."""
        return self.prints[0].raw_code, self.prints[1].raw_code

    @functools.cached_property
    def passages(self) -> tuple[tuple[Passage, ...], tuple[Passage, ...]]:
        """The matching passages of each side (worked out when asked: only the pairs shown
        in full need them)."""
        if not any(self.matched):
            return (), ()
        _, _, slices = compare_files(*self.prints)
        groups = _groups(*self.prints)
        return tuple(
            tuple(Passage(int(a), int(b), g) for a, b, g in zip(cut[0], cut[1], side))
            for cut, side in zip(slices, groups)
        )

    @property
    def similarity(self) -> float:
        """The larger of the two parts of each file's own code found in the other."""
        return max(_part(m, c) for m, c in zip(self.matched, self.code))

    def flagged(self, threshold: float) -> bool:
        return self.similarity >= threshold and max(self.matched) >= MIN_MATCHED


@dataclass(frozen=True)
class Pair:
    """Two students and the task files both handed in, compared file by file."""

    students: tuple[str, str]
    files: tuple[FileMatch, ...]
    code: tuple[int, int]  # each one's own reduced code over all their task files

    @property
    def matched(self) -> tuple[int, int]:
        """Characters of each one's reduced code found in the other's files."""
        return tuple(sum(f.matched[side] for f in self.files) for side in (0, 1))

    @property
    def shares(self) -> tuple[float, float]:
        """Part of each one's own code (all task files) found in the other's (0 .. 1)."""
        return tuple(_part(m, c) for m, c in zip(self.matched, self.code))

    @property
    def similarity(self) -> float:
        """The larger share: a copy that added code of its own is still found in the other."""
        return max(self.shares)

    def flagged(self, threshold: float) -> bool:
        """Worth a look: similar enough over all files, or in one file, and more than a line
        or two."""
        whole = self.similarity >= threshold and max(self.matched) >= MIN_MATCHED
        return whole or any(f.flagged(threshold) for f in self.files)

    def file(self, task_file: str) -> FileMatch | None:
        return next((f for f in self.files if f.task_file == task_file), None)


def _part(matched: int, code: int) -> float:
    return min(matched / code, 1.0) if code else 0.0


def task_texts(folder: Path) -> tuple[dict[str, str], list[str]]:
    """The task files of a submission the grader grades, by name, and what was left out:
    regular files only (a link is never followed), of at most `MAX_FILE_BYTES`."""
    texts, left_out = {}, []
    try:
        directory = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
    except OSError:
        return {}, [f"{folder.name} is not a folder (a link is not followed)"]
    try:
        for name in TASK_FILES:
            text, problem = _read_task_file(directory, name)
            if text is not None:
                texts[name] = text
            elif problem:
                left_out.append(problem)
    finally:
        os.close(directory)
    return texts, left_out


def _read_task_file(directory: int, name: str) -> tuple[str | None, str | None]:
    try:
        handle = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK, dir_fd=directory)
    except FileNotFoundError:
        return None, None
    except OSError:  # ELOOP: a symbolic link
        return None, f"{name} is not a regular file (a link is not followed)"
    with os.fdopen(handle, "rb") as file:
        status = os.fstat(file.fileno())
        if not stat.S_ISREG(status.st_mode):
            return None, f"{name} is not a regular file"
        data = file.read(MAX_FILE_BYTES + 1)
    if len(data) > MAX_FILE_BYTES:
        return None, f"{name} is larger than {MAX_FILE_BYTES} bytes (the grader ignores it too)"
    return data.decode("utf-8", errors="replace"), None


def compare(submissions: Mapping[str, Mapping[str, str]], templates: Path) -> list[Pair]:
    """Every pair of ``submissions`` (id -> task file name -> text), the template's text in
    ``templates`` left out; most similar first."""
    prints: dict[str, dict[str, CodeFingerprint]] = {student: {} for student in submissions}
    for task_file in TASK_FILES:
        template = _template_hashes(templates / task_file)
        for student, texts in submissions.items():
            if task_file in texts:
                prints[student][task_file] = _fingerprint(task_file, texts[task_file], template)
    code = {s: sum(int(p.token_coverage) for p in files.values()) for s, files in prints.items()}
    pairs = []
    for first, second in itertools.combinations(sorted(submissions), 2):
        files = tuple(
            _file_match(name, prints[first][name], prints[second][name])
            for name in TASK_FILES
            if name in prints[first] and name in prints[second]
        )
        pairs.append(Pair((first, second), files, (code[first], code[second])))
    return sorted(pairs, key=lambda p: (-p.similarity, -max(p.matched), p.students))


def _template_hashes(template: Path) -> list[int]:
    if not template.is_file():  # without it the given code would count as shared
        raise FileNotFoundError(f"no template {template.name} in {template.parent}")
    text = template.read_text(encoding="utf-8")
    return list(CodeFingerprint(str(template), NOISE, 1, fp=io.StringIO(text)).hashes)


def _fingerprint(name: str, text: str, template_hashes: list[int]) -> CodeFingerprint:
    # A window of 1 keeps every fingerprint: copydetect's winnowing picks by Python's hash(),
    # which differs from run to run, and so would the scores; every match >= NOISE is found.
    return CodeFingerprint(name, NOISE, 1, template_hashes, fp=io.StringIO(text))


def _file_match(task_file: str, first: CodeFingerprint, second: CodeFingerprint) -> FileMatch:
    _, shares, _ = compare_files(first, second)
    code = (int(first.token_coverage), int(second.token_coverage))
    matched = tuple(round(float(share) * count) for share, count in zip(shares, code))
    return FileMatch(task_file, code, matched, (first, second))


def _groups(first: CodeFingerprint, second: CodeFingerprint) -> tuple[list[int], list[int]]:
    """For each matching passage of each side (copydetect's order), the number (1, 2, ...) of
    its group: passages of the two files that share a fingerprint are in one group."""
    overlap = find_fingerprint_overlap(first.hashes, second.hashes, first.hash_idx, second.hash_idx)
    starts = [get_copied_slices(idx, NOISE)[0] for idx in overlap]
    count = len(starts[0])
    parent = list(range(count + len(starts[1])))  # first's passages, then second's

    def root(node: int) -> int:
        while parent[node] != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    for value in first.hashes & second.hashes:  # each place of it joined to a place of the other
        here = np.searchsorted(starts[0], first.hash_idx[value], side="right") - 1
        there = np.searchsorted(starts[1], second.hash_idx[value], side="right") - 1 + count
        for a, b in [*((a, there[0]) for a in here), *((here[0], b) for b in there)]:
            parent[root(int(b))] = root(int(a))
    numbers: dict[int, int] = {}
    grouped = [numbers.setdefault(root(node), len(numbers) + 1) for node in range(len(parent))]
    return grouped[:count], grouped[count:]


CSV_COLUMNS = ("first", "second", "similarity", "first_share", "second_share", "matched",
               "flagged", *TASK_FILES)  # fmt: skip


def write_csv(pairs: list[Pair], path: Path, threshold: float) -> None:
    """One row per pair of students, most similar first (columns `CSV_COLUMNS`; a task
    file's column is that file's similarity, empty where one of them did not hand it in).
    Every cell is written so that no spreadsheet takes it for a formula."""
    lines = []
    for pair in pairs:
        per_file = [pair.file(name) for name in TASK_FILES]
        lines.append([
            *pair.students,
            f"{pair.similarity:.2f}",
            *(f"{share:.2f}" for share in pair.shares),
            max(pair.matched),
            "yes" if pair.flagged(threshold) else "no",
            *("" if f is None else f"{f.similarity:.2f}" for f in per_file),
        ])  # fmt: skip
    csv_files.write_csv(path, lines, header=CSV_COLUMNS)
