"""``import msdlab`` shows its public names to the tools that read code (an IDE's completions)
and imports them on first use; ``msdlab check`` (a student's most frequent command) waits for
no engine in its own process, and its checks' process for nothing heavy the checks do not use."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import msdlab
from msdlab.course import PROJECT_ROOT, runner

HEAVY = {"numba", "matplotlib", "anywidget", "IPython"}
"""Packages no check of a task uses: the compiler, the pictures, the live view."""


def imported_after(code: str) -> set[str]:
    """The top-level packages a fresh Python holds after running ``code``."""
    report = "import sys; print(' '.join(sorted({m.split('.')[0] for m in sys.modules})))"
    done = subprocess.run(
        [sys.executable, "-c", f"{code}\n{report}"], capture_output=True, text=True, check=True
    )
    return set(done.stdout.split())


def test_importing_msdlab_imports_no_engine():
    assert not imported_after("import msdlab") & {"numpy", "scipy", "numba", "matplotlib"}


def test_an_editor_completes_the_public_names():
    """What an IDE offers after ``msdlab.`` (jedi, IPython's and many editors' completion
    engine, reads the code without running it)."""
    jedi = pytest.importorskip("jedi")
    script = jedi.Script("import msdlab\nmsdlab.", project=jedi.Project(PROJECT_ROOT))
    offered = {completion.name for completion in script.complete(2, len("msdlab."))}
    assert set(msdlab.__all__) <= offered


def test_a_run_imports_no_dense_linear_algebra():
    """scipy.linalg (0.3 s to import) only where a mode or an implicit step is asked for:
    not in a check that runs a body with Verlet."""
    code = "import msdlab as msd\n"
    code += "body = msd.Body.grid((3, 3), neighbours=(1,))\n"
    code += "msd.Simulation(body, msd.Verlet(), kernel='numpy').run(steps=2)\n"
    code += "import sys; print(*[m for m in sys.modules if m.startswith('scipy.linalg')])"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split() == []


def test_the_check_command_starts_without_numpy():
    code = "from msdlab.cli import build_parser, named_command\n"
    code += "build_parser(named_command(['check', '2'])).parse_args(['check', '2'])"
    assert "numpy" not in imported_after(code)


def test_the_checks_process_imports_nothing_heavy(tmp_path, monkeypatch):
    """The pytest process of ``msdlab check 2`` (the reference answers: every check runs to
    its end) imports neither the compiler nor the pictures."""
    (tmp_path / "sitecustomize.py").write_text(
        textwrap.dedent(f"""
            import atexit, sys
            atexit.register(lambda: open({str(tmp_path / "modules.txt")!r}, "w").write(
                " ".join(sorted({{name.split(".")[0] for name in sys.modules}}))))
        """)
    )
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    checks = PROJECT_ROOT / runner.CHECKS
    report, output = runner.run_checks(checks, PROJECT_ROOT / "solutions", 2)
    assert report.all_passed, output
    imported = set((tmp_path / "modules.txt").read_text().split())
    assert "pytest" in imported and not imported & HEAVY


@pytest.mark.parametrize("name", msdlab.__all__)
def test_every_public_name_is_there_when_used(name):
    value = getattr(msdlab, name)
    assert value.__name__ == name and name in dir(msdlab)


def test_a_submodule_is_there_when_used_and_a_wrong_name_is_an_attribute_error():
    assert msdlab.analysis.max_stable_dt is msdlab.max_stable_dt
    with pytest.raises(AttributeError, match="has no attribute 'Bodies'"):
        msdlab.Bodies  # noqa: B018


def test_a_star_import_gives_the_public_names():
    names: dict = {}
    exec("from msdlab import *", names)
    assert {"Body", "Simulation", "Verlet", "max_stable_dt"} <= set(names)
    assert Path(msdlab.__file__).name == "__init__.py"
