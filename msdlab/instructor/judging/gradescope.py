"""A Gradescope autograder for the course: the zip to upload and the script it runs.

`build` writes the zip: ``setup.sh`` installs msdlab from the zip itself with its
``grade`` extra (what the checks import) from the package index; ``run_autograder`` runs
``python3 -m msdlab.instructor.judging.gradescope``, which grades the student's task
files (at the top of ``/autograder/submission`` or in its ``assignments/``, taken in by `intake`)
with the instructor's checks, hidden ones included, by the same `grading.grade`
as ``msdlab grade``, and writes ``/autograder/results/results.json`` in
Gradescope's format: the total ``score``, one test per public check (``name``,
``score``, ``max_score``, ``status``, ``output`` for the student, ``visibility``), one
test per task for its hidden checks (their points only, shown as the setting
``hidden_visibility`` says), and the per-task totals in ``output`` and ``extra_data``.
A student reads there what the local feedback says: no hidden check's name or message,
no note about the grader itself (`outputs.feedback.student_notes`).

Isolation: each submission already runs in its own throw-away container on
Gradescope, which holds nothing but the autograder and that one submission, so
the container is the boundary. The sandbox's isolation level is a setting of
the zip (default ``process``: a separate process with resource limits and the
audit hook, which needs no privileges and no namespaces the container may lack).
The root of the tree (``/autograder``) is the environment variable
``MSDLAB_AUTOGRADER_ROOT``, so the script can be tried on a copy of the tree.

Own numbers: where the course gives each student their own numbers, the zip carries its
``course.json``, and each submission is graded against the numbers of its student, whose
roster id is read from Gradescope's ``submission_metadata.json`` (the user's field the
setting ``roster_id`` names: ``sid``, the student id of Gradescope's roster, or
``email``).
"""

from __future__ import annotations

import argparse
import json
import sys
import zipfile
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

from ...course import own_numbers
from ...course.report import CheckReport, CheckResult
from .. import intake
from ..outputs import feedback
from . import grading

CONFIG = "msdlab-autograder.json"
HIDDEN_VISIBILITIES = ("after_published", "hidden")
ROSTER_IDS = ("sid", "email")  # the fields of a Gradescope user that can be the roster id
METADATA = "submission_metadata.json"
ROOT_VARIABLE = "MSDLAB_AUTOGRADER_ROOT"
GRADE_EXTRA = "grade"  # the extra of pyproject.toml that running the checks needs

SETUP = f"""\
#!/usr/bin/env bash
# Gradescope runs this once when it builds the autograder image: msdlab from this zip, and
# from the package index its dependencies and what the checks need (its {GRADE_EXTRA} extra).
set -euo pipefail
cd "$(dirname "$0")"
PYTHON="${{PYTHON:-python3}}"
PACKAGES=("./msdlab[{GRADE_EXTRA}]")
"$PYTHON" -m pip install --no-cache-dir "${{PACKAGES[@]}}" \\
  || "$PYTHON" -m pip install --no-cache-dir --break-system-packages "${{PACKAGES[@]}}"
"""

RUN_AUTOGRADER = f"""\
#!/usr/bin/env bash
# Gradescope runs this for each submission: grade it into results/results.json.
exec "${{PYTHON:-python3}}" -m msdlab.instructor.judging.gradescope \\
  "${{{ROOT_VARIABLE}:-/autograder}}"
"""


@dataclass(frozen=True)
class Settings:
    """What the autograder does, stored in the zip: limits, isolation, hidden checks' visibility."""

    hidden_visibility: str = "after_published"
    isolation: str = "process"
    timeout: float = 600.0
    call_timeout: float = 60.0
    memory_mb: int = 2048
    roster_id: str = "sid"

    def __post_init__(self) -> None:
        if self.hidden_visibility not in HIDDEN_VISIBILITIES:
            raise ValueError(
                f"hidden checks' visibility is one of {', '.join(HIDDEN_VISIBILITIES)}, "
                f"got {self.hidden_visibility!r}"
            )
        if self.roster_id not in ROSTER_IDS:
            raise ValueError(
                f"the roster id is one of the Gradescope user's fields {', '.join(ROSTER_IDS)}, "
                f"got {self.roster_id!r}"
            )
        if self.timeout <= 0 or self.call_timeout <= 0 or self.memory_mb < 256:
            raise ValueError("timeout and call_timeout > 0 s and memory_mb >= 256 MB")


def build(out: Path, project: Path, checks: Path, settings: Settings) -> list[str]:
    """Write the autograder zip ``out`` for the msdlab at ``project`` and the checks in
    ``checks`` (with the settings of their course, `own_numbers.course_of`); return the
    names it holds."""
    if out.suffix != ".zip":
        raise ValueError(f"the autograder is a .zip file, got {out}")
    if not list(checks.glob("test_*.py")):
        raise FileNotFoundError(f"no checks (test_*.py) in {checks}; give --checks DIR")
    course = own_numbers.course_of(checks)
    out.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as archive:
        _add(archive, "setup.sh", SETUP)
        _add(archive, "run_autograder", RUN_AUTOGRADER)
        _add(archive, CONFIG, json.dumps(asdict(settings), indent=2) + "\n")
        if own_numbers.enabled(course):
            archive.write(course / own_numbers.SETTINGS_FILE, own_numbers.SETTINGS_FILE)
        for name in ("pyproject.toml", "README.md"):
            archive.write(project / name, f"msdlab/{name}")
        for path in _files(project / "msdlab"):
            archive.write(path, f"msdlab/{path.relative_to(project).as_posix()}")
        for path in _files(checks):
            archive.write(path, f"checks/{path.relative_to(checks).as_posix()}")
        return archive.namelist()


def results(grade: grading.Grade, hidden_visibility: str) -> dict[str, object]:
    """The results.json content for one graded submission (Gradescope's format)."""
    notes = feedback.student_notes(grade.notes)
    if grade.report is None:
        reason = "\n".join(f"- {note}" for note in notes)
        output = f"Your submission could not be graded:\n{reason}"
        test = {"name": "Grading", "score": 0, "max_score": 0, "status": "failed",
                "output": output, "visibility": "visible"}  # fmt: skip
        return {"score": 0, "output": output, "tests": [test], "extra_data": {"notes": notes}}
    tasks = {f"task{task}": {"score": grade.points(task), "max_score": _possible(grade, task)}
             for task in grade.report.tasks()}  # fmt: skip
    lines = [f"{grade.total}/{grade.report.points} points"]
    lines += [f"{name}: {t['score']}/{t['max_score']}" for name, t in tasks.items()]
    lines += [f"Note: {note}" for note in notes]
    return {
        "score": grade.total,
        "execution_time": round(grade.seconds),
        "output": "\n".join(lines),
        "tests": _tests(grade.report, hidden_visibility),
        "extra_data": {"tasks": tasks, "notes": notes},
    }


def _tests(report: CheckReport, hidden_visibility: str) -> list[dict[str, object]]:
    """Gradescope's tests: each public check with what a failing one saw; a task's hidden
    checks as one test of their points only (no name, no message), shown as
    ``hidden_visibility`` says, as the local feedback shows them."""
    tests = []
    for task in report.tasks():
        checks = [c for c in report.checks if c.task == task]
        for number, check in enumerate((c for c in checks if not c.hidden), start=1):
            tests.append({"name": f"Task {task}: {check.name}", "number": f"{task}.{number}",
                          "score": check.earned, "max_score": check.points,
                          "status": "passed" if check.passed else "failed",
                          "output": _output(check), "visibility": "visible"})  # fmt: skip
        hidden = [c for c in checks if c.hidden]
        if hidden:
            plural = "s" * (len(hidden) != 1)
            tests.append({"name": f"Task {task}: {len(hidden)} hidden check{plural}",
                          "number": f"{task}.hidden",
                          "score": sum(c.earned for c in hidden),
                          "max_score": sum(c.points for c in hidden),
                          "status": "passed" if all(c.passed for c in hidden) else "failed",
                          "output": "", "visibility": hidden_visibility})  # fmt: skip
    return tests


def run_autograder(root: Path) -> dict[str, object]:
    """Grade ``root/submission`` with the checks in ``root/source`` into
    ``root/results/results.json``; return its content."""
    source = root / "source"
    settings = Settings(**json.loads((source / CONFIG).read_text(encoding="utf-8")))
    own = own_numbers.enabled(source)
    student = roster_id(root / METADATA, settings.roster_id) if own else "submission"
    if student is None:
        problem = (
            f"the autograder found no {settings.roster_id} of yours in Gradescope's submission "
            "metadata, and each student's work is checked against their own numbers: ask "
            "your instructor to check the Gradescope roster"
        )
        grade = grading.Grade("submission", None, [problem])
    else:
        with intake.Intake() as taken:
            entry = taken.add_gradescope(root)
            grade = grading.grade(
                grading.Submission(student, entry.folder),
                source / "checks",
                timeout=settings.timeout,
                call_timeout=settings.call_timeout,
                memory_mb=settings.memory_mb,
                isolation=settings.isolation,
                own_numbers=own,
            )
    content = results(grade, settings.hidden_visibility)
    target = root / "results" / "results.json"
    target.parent.mkdir(parents=True, exist_ok=True)
    partial = target.with_suffix(".json.partial")
    partial.write_text(json.dumps(content, indent=2) + "\n", encoding="utf-8")
    partial.replace(target)
    return content


def roster_id(metadata: Path, field: str) -> str | None:
    """The ``field`` (`ROSTER_IDS`) of the submitting student in Gradescope's submission
    metadata; None where the file, the student or the field is missing."""
    try:
        users = json.loads(metadata.read_text(encoding="utf-8")).get("users") or []
        found = str(users[0].get(field) or "").strip()
    except (OSError, ValueError, AttributeError, IndexError):
        return None
    return found or None


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m msdlab.instructor.judging.gradescope [ROOT]``, what ``run_autograder`` calls."""
    parser = argparse.ArgumentParser(prog="python -m msdlab.instructor.judging.gradescope")
    parser.add_argument("root", type=Path, nargs="?", default=Path("/autograder"))
    content = run_autograder(parser.parse_args(argv).root)
    print(content["output"])
    return 0


def _files(folder: Path) -> list[Path]:
    skipped = ("__pycache__", ".pytest_cache", ".hypothesis")
    return sorted(
        path for path in folder.rglob("*")
        if path.is_file() and not any(part in skipped for part in path.parts)
    )  # fmt: skip


def _add(archive: zipfile.ZipFile, name: str, text: str) -> None:
    """A text file that Gradescope can execute (mode 755)."""
    info = zipfile.ZipInfo(name)
    info.external_attr = 0o100755 << 16
    info.compress_type = zipfile.ZIP_DEFLATED
    archive.writestr(info, text)


def _possible(grade: grading.Grade, task: int) -> int:
    assert grade.report is not None
    return sum(c.points for c in grade.report.checks if c.task == task)


def _output(check: CheckResult) -> str:
    """What the student reads: nothing for a pass, else the summary (a to-do says the file and
    function to write, and what), then the full message where it says more."""
    if check.passed:
        return ""
    full = check.message.strip()
    if check.exception == "NotImplementedError" or not full or full == check.summary:
        return check.summary
    return f"{check.summary}\n\n{full}"


if __name__ == "__main__":
    sys.exit(main())
