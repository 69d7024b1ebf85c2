"""`msdlab release`: the student bundle holds what students need and no answers, and its
own quick start works."""

from __future__ import annotations

import json
import re
import shutil
import site
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor import release
from msdlab.instructor.release_rules import solution_leaks, solution_lines


@pytest.fixture(scope="module")
def bundle(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("release") / "bundle"
    assert main(["release", str(out)]) == 0
    return out


def test_bundle_has_engine_templates_public_checks_and_no_answers(bundle):
    files = {p.relative_to(bundle).as_posix() for p in bundle.rglob("*") if p.is_file()}
    assert {"msdlab/__init__.py", "pyproject.toml", "README.md", "tests/tasks/conftest.py"} <= files
    assert {f"assignments/task{n}.py" for n in range(1, 6)} <= files
    assert {f"tests/tasks/test_task{n}.py" for n in range(1, 6)} <= files
    assert not any(f.startswith(("solutions/", "tests/course/")) for f in files)
    assert not any(f.endswith("_hidden.py") for f in files)
    shipped = [p for p in bundle.rglob("*") if p.is_file()]
    assert solution_leaks(shipped, solution_lines(PROJECT_ROOT / "solutions")) == []


def test_notebooks_ship_without_outputs_and_save_the_students(bundle):
    """No outputs of the solutions; marked as the students', so their Jupyter saves their
    outputs."""
    notebooks = sorted((bundle / "notebooks").glob("*.ipynb"))
    if not (PROJECT_ROOT / "notebooks").is_dir():
        pytest.skip("the course has no notebooks yet")
    assert notebooks
    for path in notebooks:
        notebook = json.loads(path.read_text())
        code = [c for c in notebook["cells"] if c["cell_type"] == "code"]
        assert all(c.get("outputs", []) == [] for c in code), path
        mark = {"save_outputs": True, "file": path.name}
        assert notebook["metadata"]["msdlab"] == mark, path


def test_a_solution_line_anywhere_stops_the_release(tmp_path):
    course = tmp_path / "course"
    for part in ("msdlab", "solutions", "assignments", "tests/tasks"):
        shutil.copytree(
            PROJECT_ROOT / part, course / part, ignore=shutil.ignore_patterns("__pycache__")
        )
    shutil.copy(PROJECT_ROOT / "pyproject.toml", course)
    leaked = max(solution_lines(course / "solutions"), key=len)
    with (course / "assignments" / "task2.py").open("a") as handle:
        handle.write(f"\n# {leaked}\n    {leaked}\n")
    out = tmp_path / "bundle"
    with pytest.raises(release.ReleaseError, match=r"assignments/task2\.py"):
        release.build(out, course)
    assert not out.exists()


def test_release_refuses_a_non_empty_folder_and_the_course_itself(tmp_path):
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "keep.txt").write_text("x")
    with pytest.raises(FileExistsError, match="--force"):
        release.build(tmp_path / "old", PROJECT_ROOT)
    with pytest.raises(ValueError, match="outside the course"):
        release.build(PROJECT_ROOT / "release", PROJECT_ROOT)


def test_the_bundles_quick_start_works(bundle, tmp_path):
    """pip install -e . && msdlab demo; msdlab check reports what is to do (exit 1)."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python, scripts = venv / "bin" / "python", venv / "bin"
    packages = subprocess.check_output(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], text=True
    ).strip()
    # the new environment borrows this one's libraries instead of downloading them
    (Path(packages) / "borrowed.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    subprocess.run(
        [
            python,
            "-m",
            "pip",
            "install",
            "-q",
            "--no-deps",
            "-e",
            str(bundle),
        ],
        check=True,
    )
    where = subprocess.check_output(
        [python, "-c", "import msdlab; print(msdlab.__file__)"], text=True, cwd=tmp_path
    )
    assert Path(where.strip()).is_relative_to(bundle)
    demo = subprocess.run(
        [scripts / "msdlab", "demo"], cwd=bundle, capture_output=True, text=True, timeout=300
    )
    assert demo.returncode == 0, demo.stderr
    check = subprocess.run(
        [scripts / "msdlab", "check"], cwd=bundle, capture_output=True, text=True, timeout=600
    )
    assert check.returncode == 1, check.stderr
    assert "to do in assignments/" in check.stdout and "total: 0/" in check.stdout
    assert "hidden checks worth" in check.stdout and "more run when graded" in check.stdout
    hidden = subprocess.run(
        [scripts / "msdlab", "check", "1", "--hidden"], cwd=bundle, capture_output=True, text=True
    )
    assert hidden.returncode == 2 and "hidden checks are not in this copy" in hidden.stdout
    helped = subprocess.run([scripts / "msdlab", "check", "--help"], capture_output=True, text=True)
    assert "--task-timeout" in helped.stdout and "--hidden" not in helped.stdout
    usage = subprocess.run([scripts / "msdlab", "--help"], capture_output=True, text=True)
    listed = re.findall(r"^    (\w+)", usage.stdout, flags=re.MULTILINE)
    assert listed == ["demo", "scenes", "run", "check", "handin"], usage.stdout
    handin = subprocess.run(
        [scripts / "msdlab", "handin"], cwd=bundle, capture_output=True, text=True
    )
    assert handin.returncode == 0 and "parts still the template's" in handin.stdout, handin.stderr
    with zipfile.ZipFile(bundle / "handin.zip") as archive:
        assert sorted(archive.namelist()) == [f"assignments/task{n}.py" for n in range(1, 6)]
    (bundle / "handin.zip").unlink()


def test_bundle_readme_and_gitignore(bundle):
    readme = (bundle / "README.md").read_text()
    assert "rest length one grid spacing" in readme and "rest length 1 " not in readme
    ignored = (bundle / ".gitignore").read_text().split()
    assert {".venv/", "msdlab-output/", "__pycache__/", ".hypothesis/"} <= set(ignored)
    points = json.loads((bundle / "tests" / "tasks" / "points.json").read_text())
    assert all(counts["hidden"] > 0 for counts in points["tasks"].values())


def test_the_bundle_carries_the_brief_and_the_student_pages_linked_from_its_readme(bundle):
    """The README's quick start starts with a virtual environment; every relative link of
    the README and of the pages in docs/ leads to a file of the bundle; the brief's
    equations (1.1)-(1.4), which the tasks cite, are there; no site-only syntax is left."""
    readme = (bundle / "README.md").read_text()
    assert "```bash\npython3 -m venv .venv && . .venv/bin/activate\n" in readme
    brief = (bundle / "docs" / "brief.md").read_text()
    assert all(f"\\tag{{1.{n}}}" in brief for n in (1, 2, 3, 4))
    pages = [bundle / "README.md", *sorted((bundle / "docs").glob("*.md"))]
    assert len(pages) > 5
    for page in pages:
        text = page.read_text()
        assert "{toctree}" not in text and "{py:obj}" not in text, page
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            path = target.partition("#")[0]
            if path and not re.match(r"[a-z]+:", path):
                assert (page.parent / path).is_file(), f"{page.name} links to {target}"
    assert "docs/brief.md" in readme and "docs/index.md" in readme


PLACEHOLDERS = {"N": "2", "DIR": "assignments", "S": "10", "SCENE": "jelly-cube", "NAME": "*"}
"""What a page's placeholder stands for, to try its command or find its path."""
MADE_LATER = {
    "msdlab-output/": "msdlab demo writes it",
    ".venv/": "the quick start's first line makes it",
    "assignments/student.json": "a release with its own numbers holds it",
}
"""Paths a release page names that the student's own commands make, not the release."""
CODE = re.compile(r"(?<!`)`([^`\n]+)`(?!`)")
BLOCK = re.compile(r"^```(?:bash|console|sh|shell)\n(.*?)^```", re.M | re.S)
PATH = re.compile(r"^[\w.-]+/[\w./*-]*$")


def named_in(text: str) -> list[str]:
    """The inline code and the shell lines of a page, placeholders filled in."""
    lines = [line.split(" # ")[0].strip() for block in BLOCK.findall(text)
             for line in block.splitlines()]  # fmt: skip
    named = [*CODE.findall(text), *(line for line in lines if line)]
    return [" ".join(PLACEHOLDERS.get(word, word) for word in item.split()) for item in named]


def not_in_release(command: str, bundle: Path, parser) -> str:
    """Why ``command`` (or path) named by a release page does not work there; '' if it does."""
    words = command.split()
    if words[0] == "msdlab":
        try:
            parser.parse_args(words[1:])
        except SystemExit as done:  # --help exits 0
            return f"msdlab does not take `{command}`" if done.code else ""
    elif words[0] in ("python", "python3") and words[1].endswith(".py"):
        return "" if (bundle / words[1]).is_file() else f"`{command}`: no {words[1]} there"
    elif PATH.match(command) and command not in MADE_LATER:
        return "" if list(bundle.glob(command.rstrip("/"))) else f"`{command}` is not there"
    return ""


def test_every_command_and_path_a_release_page_names_is_in_the_release(bundle):
    """The release's README and pages name only what the release has: each msdlab command
    is one its msdlab takes (--hidden, which has nothing to run there, is not offered),
    each script and path is a file of the release, from the folder the pages say to stand
    in (the release's)."""
    from msdlab.cli import build_parser
    from msdlab.commands import STUDENT_COMMANDS

    parser = build_parser(STUDENT_COMMANDS)
    wrong = []
    for page in [bundle / "README.md", *sorted((bundle / "docs").glob("*.md"))]:
        text = page.read_text(encoding="utf-8")
        if "--hidden" in text or "notebooks/src" in text or "build.py" in text:
            wrong.append(f"{page.name}: names what only a clone of the course has")
        commands = [command for item in named_in(text) for command in item.split(" && ")]
        wrong += [
            f"{page.name}: {why}" for c in commands if (why := not_in_release(c, bundle, parser))
        ]
    assert not wrong, "\n".join(wrong)
