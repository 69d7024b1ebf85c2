"""Every shell command of the instructor's and the student's pages, and of the site's first
page, typed as written from the place the page says to stand.

Each page with commands says where they run ("Commands on this page run from the course
folder `course/`", "... in your course folder", "... in the root of your clone"). The
walk lays out that place as the pages describe it: a folder ``course/`` holding a clone
``msdlab/`` of this repository, a class in ``class/`` (alice: the solutions, bob: the
templates, carol: a zip), the roster and the extensions file; the student's course
folder is the release ``course/student-bundle`` that the instructor's page builds. The
pages are walked in the order a term goes (the instructor's set-up first), each in one
terminal `Session`: a typed ``python3 -m venv .venv && source .venv/bin/activate`` makes
the environment the later commands run in (borrowing this Python's packages: nothing is
downloaded). A command passes with exit status 0, or 1 for the checks of work not yet
done; the ones that cannot run here are listed in `SKIPPED` with the reason. At the end
the clone is as git has it: nothing a command wrote is inside it.
"""

from __future__ import annotations

import re
import shutil
import zipfile
from pathlib import Path

import pytest
from harness import ROOT, Session, Typed

from msdlab.course import own_numbers

pytestmark = [
    pytest.mark.timeout(3600),
    pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed"),
]

DOCS = ROOT / "docs"
INSTRUCTOR = [
    "course", "templates", "grading", "similarity", "clusters", "late-work", "manual-changes",
    "export", "gradescope", "validate", "mistakes", "own-numbers", "sandbox",
    "grading-time", "adapting", "index",
]  # fmt: skip
"""The instructor's pages in the order of a term (own numbers last: it switches them on; the
pages that grade again without a due date before the late work's, which grades with one)."""
STUDENT = ["install", "check", "notebooks", "index", "tasks", "feedback", "live-view", "brief",
           "questions"]  # fmt: skip
PLACE = re.compile(r"Commands on this page run (?:from|in) (?P<place>[^:.(]+)")
PLACES = {
    "the course folder `course/`": "course",
    "your course folder": "student",
    "the root of your clone": "clone",
}
SKIPPED = {
    "msdlab validate": "minutes a task: every mutant runs its checks (test_validate.py)",
    "msdlab validate 2": "minutes a task (tests/course/test_validate.py runs validate)",
    "msdlab validate 2 --sample 40 --seed 1": "minutes (tests/course/test_validate.py)",
    "msdlab validate 3 --verbose": "minutes (tests/course/test_validate.py)",
    "python benchmarks/class_grading.py": (
        "a class of 100, about ten minutes on two cores (the page's --count 6 line runs)"
    ),
    "dask scheduler": "a server that runs until it is stopped",
    "dask worker tcp://scheduler:8786 --nthreads 1": "needs a machine named scheduler",
    "msdlab grade submissions/* --out grades.csv --cluster tcp://scheduler:8786": (
        "needs the Dask scheduler at tcp://scheduler:8786 (tests/scale/test_cluster.py runs one)"
    ),
    'pip install -e ".[notebooks]" && jupyter lab notebooks/': (
        "opens JupyterLab in a browser (tests/journeys/test_student.py drives it headless)"
    ),
    'pip install -e ".[test]" && pytest -n auto': (
        "the whole test suite, this test among it (an hour on two cores)"
    ),
}
CHECKS = ("msdlab check", "pytest tests/tasks")
"""Commands that exit 1 while the work is not done: the student's files are the templates."""
ROSTER = """\
id,folder,name,email,sis_id,section
alice,class/alice,Alice Doe,alice@uni.example,S1001,A
bob,class/bob,"Doe, Bob",bob@uni.example,S1002,A
carol,class/carol.zip,Carol Roe,carol@uni.example,S1003,B
"""
CLASS_ROSTER = "id,submission\nalice,alice/assignments\nbob,bob/assignments\ncarol,carol.zip\n"
EXTENSIONS = "id,extension,due,reason\nalice,2d,,illness (certificate on file)\n"


def commands(page: Path) -> list[str]:
    """The command lines of ``page``'s shell blocks as typed: continuation lines joined,
    prompts and comments dropped."""
    text = page.read_text(encoding="utf-8")
    found = []
    for block in re.findall(r"^```(?:bash|console|sh|shell)\n(.*?)^```", text, re.M | re.S):
        for line in block.replace("\\\n", " ").splitlines():
            line = re.sub(r"\s+# .*$", "", line.strip().removeprefix("$ ")).strip()
            if line and not line.startswith("#"):
                found.append(" ".join(line.split()))
    return found


def place(page: Path) -> str | None:
    """Where ``page`` says its commands run (a key of the walk's places)."""
    said = PLACE.search(" ".join(page.read_text(encoding="utf-8").split()))
    if said is None:
        return None
    return next(key for text, key in PLACES.items() if said["place"].strip().startswith(text))


def pages() -> list[Path]:
    return [DOCS / "instructor" / f"{name}.md" for name in INSTRUCTOR] + [
        DOCS / "student" / f"{name}.md" for name in STUDENT
    ]


def test_every_page_with_commands_says_where_to_stand():
    every = [*DOCS.glob("instructor/*.md"), *DOCS.glob("student/*.md"), DOCS / "index.md"]
    assert sorted(every) == sorted([*pages(), DOCS / "index.md"]), "a page is not walked"
    silent = [p.relative_to(DOCS) for p in every if commands(p) and place(p) is None]
    assert not silent, f"{silent} do not say where their commands run"


@pytest.fixture(scope="module")
def course(tmp_path_factory) -> Path:
    """``course/``: the clone ``msdlab/``, a class of three, the roster and extensions."""
    course = tmp_path_factory.mktemp("term") / "course"
    course.mkdir()
    room = course / "class"
    for student, source in (("alice", "solutions"), ("bob", "assignments")):
        shutil.copytree(ROOT / source, room / student / "assignments",
                        ignore=shutil.ignore_patterns("__pycache__", "*.json"))  # fmt: skip
    with zipfile.ZipFile(room / "carol.zip", "w") as bundle:
        for path in sorted((ROOT / "assignments").glob("task*.py")):
            bundle.write(path, f"assignments/{path.name}")
    (room / "roster.csv").write_text(CLASS_ROSTER)
    (course / "roster.csv").write_text(ROSTER)
    (course / "extensions.csv").write_text(EXTENSIONS)
    return course


def typed_as_written(session: Session, command: str, cwd: Path, clone: Path) -> Typed | None:
    """``command`` typed in ``cwd`` (None where it is skipped), with the clone's address
    for the placeholder of the repository and the student's folder for ``DIR``."""
    if command in SKIPPED:
        return None
    command = command.replace("<your msdlab repository>", str(clone))
    command = command.replace("--impl DIR", "--impl assignments")
    return session.type(command, cwd, timeout=900)


def passed(done: Typed) -> bool:
    if done.status == 0:
        return True
    return done.status == 1 and any(check in done.command for check in CHECKS)


def test_every_documented_command_works_from_where_its_page_says(course, tmp_path):
    """The instructor's pages from ``course/``, the student's in the release they built, the
    site's first page in the clone; then the clone is as git has it."""
    instructor = Session()
    student = Session()
    places = {"course": course, "student": course / "student-bundle"}
    ran, skipped, failed = [], [], []
    for page in [*pages(), DOCS / "index.md"]:
        lines = commands(page)
        if not lines:
            continue
        where = place(page)
        session = student if where == "student" else instructor
        folder = places.get(where, course / "msdlab")
        if page.stem == "own-numbers":  # the page's switch, in the clone's course.json
            (course / "msdlab" / own_numbers.SETTINGS_FILE).write_text('{"own_numbers": true}')
        for command in lines:
            done = typed_as_written(session, command, folder, ROOT)
            if done is None:
                skipped.append(command)
            elif passed(done):
                ran.append(command)
            else:
                failed.append(f"{page.relative_to(DOCS)}, in {folder.name}/:\n{done}")
        (course / "msdlab" / own_numbers.SETTINGS_FILE).unlink(missing_ok=True)
    assert not failed, "\n\n".join(failed)
    assert sorted(set(skipped)) == sorted(SKIPPED), "a skipped command is no longer documented"
    assert len(ran) >= 30, ran
    status = instructor.type("git status --porcelain --untracked-files=all", course / "msdlab")
    assert status.status == 0 and status.output.strip() == "", status
