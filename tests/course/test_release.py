"""`msdlab release`: the student bundle holds what students need and no answers, and its
own quick start works."""

from __future__ import annotations

import json
import re
import shutil
import site
import subprocess
import sys
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
    assert "hidden checks are not in this copy" in hidden.stdout and "(hidden)" not in hidden.stdout
    usage = subprocess.run([scripts / "msdlab", "--help"], capture_output=True, text=True)
    listed = re.findall(r"^    (\w+)", usage.stdout, flags=re.MULTILINE)
    assert listed == ["demo", "scenes", "run", "check"], usage.stdout


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
