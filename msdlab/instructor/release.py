"""The student release: the engine, the templates, the notebooks and the public checks.

`build` copies what ships (see `release_rules`) into a new folder, the notebooks
without outputs and marked as the students' (their outputs are saved), writes the students'
README, ``.gitignore``, pyproject and the points manifest (what the hidden
checks, which do not ship, are worth), and refuses to finish if any line of a solution block
turns up anywhere in the bundle.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from ..course import manifest, notebook_file, notebook_source, own_numbers
from ..course.runner import CHECKS
from . import release_docs, templates
from .release_rules import shipped_files, solution_leaks, solution_lines

STUDENT_README = """\
# msdlab: mass-spring-damper course

Elastic bodies as particles joined by springs, integrated in time. You will
turn a template that drops a grid of particles onto the floor into a jelly
cube, in five staged tasks.

## Quick start

In a terminal, in this folder (the one holding this README):

```bash
python3 -m venv .venv && . .venv/bin/activate
pip install -e . && msdlab demo
pip install -e ".[grade]" && msdlab check
```

The first line makes a virtual environment in `.venv/` and activates it:
msdlab and what it needs are installed there, not into your system's Python
(which Debian and Ubuntu refuse). In a new terminal, activate it again with
`. .venv/bin/activate` (on Windows: `.venv\\Scripts\\activate`). The second
line installs msdlab and drops a jelly cube on the floor (it prints the energy
ledger and saves an animation in `msdlab-output/`). The third installs what
the checks need (pytest and hypothesis: the `grade` extra, the same that grades
your work) and runs the checks of all five tasks on your files in
`assignments/`: until you write them, each check says what is still to do.

## Your work

The tasks and the equations (1.1)-(1.4) they cite are those of
[the brief](docs/brief.md).

| task | file | what you write |
| --- | --- | --- |
| 1 | `assignments/task1.py` | answers about the template's `msd_kernel` (eq. 1.3) |
| 2 | `assignments/task2.py` | spring acceleration, eq. (1.1)-(1.2), rest length one grid spacing |
| 3 | `assignments/task3.py` | a rotated layout, and what axis springs alone do with it |
| 4 | `assignments/task4.py` | √2 and √3 neighbours, and what they cost |
| 5 | `assignments/task5.py` | Verlet with damping, eq. (1.3)-(1.4), as an integrator |

Fill in the lines that raise `NotImplementedError`, keeping names and
signatures, then check one task at a time: `msdlab check 2`. Each call into
your files may take a few seconds (`--call-timeout S` to change); the last
line shows your public points and what the hidden checks, which run when
your work is graded, are worth. The notebooks in `notebooks/` walk through
each task with plots and animations; install JupyterLab with them (the
`notebooks` extra, in the same environment) and open them:

```bash
pip install -e ".[notebooks]" && jupyter lab notebooks
```

They open on the environment's Python kernel ("Python 3 (ipykernel)").

## Handing in

The grader reads your task files `assignments/task1.py` ... `task5.py` and nothing
else. In this folder:

```bash
msdlab handin
```

writes `handin.zip` (a few kB) holding exactly those files, lists them, and warns about a
task file that is missing or still has parts of its template to write. Hand in the way
your course asks:

- **a zip file** (a learning platform, e-mail): upload `handin.zip`. Do not zip this
  whole folder: with its `.venv/` that is hundreds of MB, and the grader reads only the
  task files;
- **Gradescope**: upload `handin.zip` (or the five task files) to the assignment;
- **a folder** (a shared drive): hand in your `assignments/` folder;
- **git** (a course repository, e.g. GitHub Classroom): this folder is not a repository;
  clone the one your course gives you, copy your task files into its `assignments/`,
  then `git add assignments/task*.py`, `git commit` and `git push`. What is graded is
  the last commit pushed before the deadline.
{docs}"""

STUDENT_DOCS = """
## Documentation

The student pages, in `docs/`: [start here](docs/index.md),
[installing](docs/install.md), [the brief](docs/brief.md),
[the five tasks](docs/tasks.md), [checking your work](docs/check.md),
[reading the feedback](docs/feedback.md), [the notebooks](docs/notebooks.md),
[the live view](docs/live-view.md) and [the brief's questions](docs/questions.md).
"""

STUDENT_GITIGNORE = """\
# virtual environments
.venv/
venv/
env/
# what msdlab writes
msdlab-output/
handin.zip
*.gif
*.mp4
# caches and build by-products
__pycache__/
*.py[cod]
.pytest_cache/
.hypothesis/
.ipynb_checkpoints/
*.egg-info/
build/
dist/
"""


STUDENT_EXTRAS = ("grade", "notebooks")
"""The extras of pyproject.toml that students use: the checks' tools and JupyterLab."""

EXTRAS_TABLE = "[project.optional-dependencies]"


class ReleaseError(RuntimeError):
    """The bundle would contain something students must not get."""


def build(out: Path, root: Path, force: bool = False, student: str | None = None) -> list[Path]:
    """Write the student release of the course at ``root`` into ``out``; return its files.

    Where the course gives each student their own numbers (`own_numbers.enabled`), the
    release is one ``student``'s: their numbers in the templates, their id beside them.
    """
    out, root = Path(out).resolve(), Path(root).resolve()
    own = own_numbers.enabled(root)
    if own != (student is not None):
        raise ValueError(
            f"{root / own_numbers.SETTINGS_FILE} gives each student their own numbers: build "
            f"one release per student with --student ID (the roster id), e.g. msdlab release "
            f"{Path(out).name}/alice --student alice"
            if own
            else "--student is for a course that gives each student their own numbers: set "
            f'"own_numbers": true in {root / own_numbers.SETTINGS_FILE}, or leave --student out'
        )
    if out == root or root in out.parents:
        raise ValueError(f"write the release outside the course folder {root}")
    if out.exists() and any(out.iterdir()):
        if not force:
            raise FileExistsError(f"{out} is not empty; give another folder or --force")
        shutil.rmtree(out)
    written = []
    for source in shipped_files(root):
        target = out / source.relative_to(root)
        target.parent.mkdir(parents=True, exist_ok=True)
        if source.suffix == ".ipynb":
            _write_for_students(source, target, own_numbers.numbers(student))
        else:
            shutil.copyfile(source, target)
        written.append(target)
    if not (out / "pyproject.toml").exists():
        pyproject = (root / "pyproject.toml").read_text(encoding="utf-8")
        (out / "pyproject.toml").write_text(student_pyproject(pyproject), encoding="utf-8")
        written.append(out / "pyproject.toml")
    if student is not None:
        written.append(_personalise(out / "assignments", root / "solutions", student))
    pages = release_docs.write(root, out)
    readme = STUDENT_README.format(docs=STUDENT_DOCS if pages else "")
    (out / "README.md").write_text(readme, encoding="utf-8")
    written += pages
    (out / ".gitignore").write_text(STUDENT_GITIGNORE, encoding="utf-8")
    points = out / CHECKS / manifest.FILE_NAME
    write_points(root / CHECKS, points)
    written += [out / "README.md", out / ".gitignore", points]
    leaks = solution_leaks(written, solution_lines(root / "solutions"))
    if leaks:
        shutil.rmtree(out)
        found = "\n  ".join(str(leak).replace(f"{out}/", "") for leak in leaks)
        raise ReleaseError(f"solution text found in the release:\n  {found}")
    return sorted(written)


def student_pyproject(text: str) -> str:
    """pyproject.toml's text with only the extras students use (`STUDENT_EXTRAS`): no test,
    documentation or cluster tools to install. Each extra keeps the comment above it."""
    lines = text.splitlines(keepends=True)
    start = lines.index(EXTRAS_TABLE + "\n") + 1
    kept, pending, keep, depth = lines[:start], [], True, 0
    for index in range(start, len(lines)):
        line = lines[index]
        if depth == 0 and line.startswith("["):  # the next table
            return "".join(kept + pending + lines[index:])
        if depth == 0 and (line.startswith("#") or not line.strip()):
            pending.append(line)
            continue
        if depth == 0:
            keep = line.split("=")[0].strip() in STUDENT_EXTRAS
            kept += pending if keep else [p for p in pending if not p.strip()]
            pending = []
        depth += line.count("[") - line.count("]")
        if keep:
            kept.append(line)
    return "".join(kept + pending)


def _personalise(assignments: Path, solutions: Path, student: str) -> Path:
    """Write the templates with ``student``'s own numbers, made from ``solutions`` as the
    course's are; write their id beside them."""
    for name, text in templates.render(solutions, own_numbers.numbers(student)).items():
        (assignments / name).write_text(text, encoding="utf-8")
    return own_numbers.write_student(assignments, student)


def write_points(checks: Path, path: Path) -> None:
    """The points manifest of every check, hidden ones included (`msdlab.course.manifest`),
    from collecting the course's checks; the hidden check files themselves do not ship."""
    path.parent.mkdir(parents=True, exist_ok=True)
    command = [
        sys.executable, "-m", "pytest", str(checks), "--collect-only", "-q", "-o", "addopts=",
        "-p", "no:cacheprovider", "-p", "no:nbval", f"--msdlab-points={path}",
    ]  # fmt: skip
    environment = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    done = subprocess.run(command, cwd=checks, env=environment, capture_output=True, text=True)
    if done.returncode != 0 or not path.is_file():
        raise ReleaseError(f"the checks in {checks} could not be collected:\n{done.stdout[-2000:]}")


def _write_for_students(source: Path, target: Path, own: own_numbers.Numbers) -> None:
    """Copy a notebook without outputs or execution counts (a run in the checkout shows the
    solutions'), its cells made from its source (``src/NAME.py`` beside it) with the
    student's numbers ``own``, marked as the students' copy: their Jupyter saves their
    outputs, and no metadata of its own (`notebook_file`)."""
    notebook = json.loads(source.read_text(encoding="utf-8"))
    cells = source.parent / "src" / f"{source.stem}.py"
    if cells.is_file():
        notebook["cells"] = notebook_source.notebook_cells(cells, own)
    notebook_file.as_kept(notebook, source.name)
    notebook_file.for_students(notebook, source.name)
    target.write_text(json.dumps(notebook, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
