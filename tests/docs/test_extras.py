"""The pip extras of pyproject.toml: each reader's extra installs what their commands import,
and every extra a page or a message names exists and is stated in the README and the docs.

What a command imports is measured, not listed: a fresh interpreter imports the modules, and
each third-party module it then holds must come from a distribution that msdlab's own
dependencies and the extra require (directly or through their dependencies).
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import zipfile
from importlib import metadata
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

from msdlab.instructor import release
from msdlab.instructor.judging import gradescope

tomllib = pytest.importorskip("tomllib", reason="reads pyproject.toml with Python 3.11's tomllib")

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
EXTRAS = PROJECT["optional-dependencies"]
# `.[grade]`, ".[grade,notebooks]", 'msdlab[cluster]', `./msdlab[grade]`
NAMED_EXTRA = re.compile(r"(?:\.|msdlab)\[([\w,-]+)\]")

# Imports ``modules`` in a Python where the modules of the distributions not allowed cannot
# be imported, as in a fresh environment without them (an optional import falls back).
IMPORTS = """
import sys
sys.path.insert(0, {ext!r})
blocked = set({blocked!r})


class Absent:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in blocked:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)


sys.meta_path.insert(0, Absent())
for module in {modules!r}:
    __import__(module)
"""


def import_error(modules: list[str], allowed: set[str]) -> str:
    """What importing ``modules`` raises with only the ``allowed`` distributions installed."""
    owners = metadata.packages_distributions()
    blocked = sorted(
        name for name, dists in owners.items()
        if name != "msdlab" and not {canonicalize_name(d) for d in dists} & allowed
    )  # fmt: skip
    code = IMPORTS.format(ext=str(DOCS / "_ext"), blocked=blocked, modules=modules)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    return done.stderr.strip().splitlines()[-1] if done.returncode else ""


def required_closure(requirements: list[str]) -> set[str]:
    """The distributions these requirements bring, with everything they require in turn."""
    found: set[str] = set()
    todo = [Requirement(text) for text in requirements]
    while todo:
        requirement = todo.pop()
        name = canonicalize_name(requirement.name)
        if name in found:
            continue
        found.add(name)
        extras = requirement.extras or {""}
        for text in metadata.requires(requirement.name) or []:
            nested = Requirement(text)
            if nested.marker is None or any(nested.marker.evaluate({"extra": e}) for e in extras):
                todo.append(nested)
    return found


def extra_requirements(extra: str) -> list[str]:
    """msdlab's dependencies and those of one of its extras, as pyproject.toml states them
    (an extra that names others of msdlab's brings theirs)."""
    found = list(PROJECT["dependencies"])
    for text in EXTRAS[extra]:
        requirement = Requirement(text)
        if requirement.name == "msdlab":
            found += [r for other in sorted(requirement.extras) for r in extra_requirements(other)]
        else:
            found.append(text)
    return found


def conf_names(name: str) -> object:
    """A top-level assignment of docs/conf.py, read without running it."""
    tree = ast.parse((DOCS / "conf.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", None) == name:
            return ast.literal_eval(node.value)
    raise LookupError(name)


def top_level_imports(path: Path) -> set[str]:
    """The top-level packages a Python file imports (absolute imports only)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module.split(".")[0])
    return found


def test_the_docs_extra_holds_what_the_site_build_imports():
    """conf.py's extensions and theme, every module the API reference lists (autosummary
    imports each), and what the gallery's scenes import."""
    modules = [*conf_names("extensions"), conf_names("html_theme")]
    modules += re.findall(r"^   (msdlab[\w.]*)$", (DOCS / "api" / "index.md").read_text(), re.M)
    for scene in sorted((DOCS / "scenes").glob("*.py")):
        modules += sorted(top_level_imports(scene) - set(sys.stdlib_module_names))
    error = import_error(modules, required_closure(extra_requirements("docs")))
    assert not error, f"with only the docs extra installed: {error}"


def test_the_grade_extra_holds_what_the_checks_import():
    """msdlab check, msdlab grade and the Gradescope autograder: the judge's pytest plugins
    and every module the course's checks import."""
    checks = ROOT / "tests" / "tasks"
    local = {path.stem for path in checks.glob("*.py")}
    modules = ["msdlab.course.pytest_plugin", "msdlab.instructor.judging.pytest_sandbox"]
    for path in sorted(checks.glob("*.py")):
        modules += sorted(top_level_imports(path) - set(sys.stdlib_module_names) - local)
    error = import_error(modules, required_closure(extra_requirements("grade")))
    assert not error, f"with only the grade extra installed: {error}"


def test_the_test_extra_holds_every_other_extra_but_the_benchmarks_peers():
    others = {canonicalize_name(name) for name in EXTRAS} - {"test", "bench"}
    (brought,) = [Requirement(r) for r in EXTRAS["test"] if Requirement(r).name == "msdlab"]
    assert set(brought.extras) == others


def test_the_autograder_installs_msdlab_with_the_grade_extra(tmp_path):
    checks = tmp_path / "checks"
    checks.mkdir()
    (checks / "test_task1.py").write_text("def test_nothing():\n    pass\n")
    out = tmp_path / "autograder.zip"
    gradescope.build(out, ROOT, checks, gradescope.Settings())
    with zipfile.ZipFile(out) as archive:
        setup = archive.read("setup.sh").decode()
        zipped = tomllib.loads(archive.read("msdlab/pyproject.toml").decode())
    assert 'PACKAGES=("./msdlab[grade]")' in setup
    assert zipped["project"]["optional-dependencies"]["grade"] == EXTRAS["grade"]


def test_the_student_release_offers_only_what_students_use():
    pyproject = release.student_pyproject((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    offered = tomllib.loads(pyproject)["project"]["optional-dependencies"]
    assert offered == {name: EXTRAS[name] for name in ("grade", "notebooks")}
    named = {e for group in NAMED_EXTRA.findall(release.STUDENT_README) for e in group.split(",")}
    assert named == set(offered)


def test_pytest_knows_the_release_configs_options_with_the_grade_extra(tmp_path):
    """A student (or the autograder) runs pytest with the release's pyproject.toml and only
    the grade extra installed: every option of its pytest config is known, no warning."""
    pyproject = release.student_pyproject((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    (tmp_path / "pyproject.toml").write_text(pyproject, encoding="utf-8")
    (tmp_path / "test_nothing.py").write_text("def test_nothing():\n    pass\n")
    allowed = required_closure(extra_requirements("grade"))
    absent = [
        f"-p no:{plugin.name}" for plugin in metadata.entry_points(group="pytest11")
        if canonicalize_name(plugin.dist.name) not in allowed
    ]  # fmt: skip
    command = [sys.executable, "-m", "pytest", "--collect-only", "-q", *" ".join(absent).split()]
    done = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout
    assert "Unknown config option" not in done.stdout + done.stderr, done.stdout


def documented_pages() -> list[Path]:
    pages = [ROOT / "README.md", *DOCS.rglob("*.md"), *(ROOT / "msdlab").rglob("*.py")]
    return [page for page in pages if "_build" not in page.parts]


@pytest.mark.parametrize("page", documented_pages(), ids=lambda page: str(page.relative_to(ROOT)))
def test_every_extra_a_page_names_exists(page):
    named = {e for group in NAMED_EXTRA.findall(page.read_text(encoding="utf-8"))
             for e in group.split(",")}  # fmt: skip
    assert named <= set(EXTRAS), f"{sorted(named - set(EXTRAS))} are not extras of msdlab"


@pytest.mark.parametrize("page", ["README.md", "docs/index.md"])
def test_every_extra_is_stated(page):
    text = (ROOT / page).read_text(encoding="utf-8")
    stated = {e for group in NAMED_EXTRA.findall(text) for e in group.split(",")}
    assert stated >= set(EXTRAS), f"{page} does not state {sorted(set(EXTRAS) - stated)}"


EXTRA_ROW = re.compile(r'^\| `pip install -e "\.\[(\w+)\]"` \|[^|]*\| ([^|]*) \|$', re.M)
SAID_AS = {"pydata-sphinx-theme": "theme"}  # how a page's table names a distribution


@pytest.mark.parametrize("page", ["README.md", "docs/index.md"])
def test_each_extras_row_names_every_distribution_it_installs(page):
    """The table's "adds" column of each extra names every distribution pyproject.toml gives
    that extra (the test extra's row names the other extras instead)."""
    rows = EXTRA_ROW.findall((ROOT / page).read_text(encoding="utf-8"))
    assert {extra for extra, _ in rows} == set(EXTRAS), f"{page} has no row for some extras"
    for extra, adds in rows:
        named = [Requirement(text).name for text in EXTRAS[extra]]
        unsaid = [
            name for name in named
            if name != "msdlab" and SAID_AS.get(name, name).lower() not in adds.lower()
        ]  # fmt: skip
        assert not unsaid, f"{page}: the [{extra}] row does not say it installs {unsaid}"
