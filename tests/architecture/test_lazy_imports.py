"""``import msdlab`` and a command's start import only what they use: the public names load
on first use, and ``msdlab check`` (a student's most frequent command) waits for no engine."""

from __future__ import annotations

import subprocess
import sys

import pytest

import msdlab


def imported_after(code: str) -> set[str]:
    """The top-level packages a fresh Python holds after running ``code``."""
    report = "import sys; print(' '.join(sorted({m.split('.')[0] for m in sys.modules})))"
    done = subprocess.run(
        [sys.executable, "-c", f"{code}\n{report}"], capture_output=True, text=True, check=True
    )
    return set(done.stdout.split())


def test_importing_msdlab_imports_no_engine():
    assert not imported_after("import msdlab") & {"numpy", "scipy", "numba", "matplotlib"}


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


@pytest.mark.parametrize("name", msdlab.__all__)
def test_every_public_name_is_there_when_used(name):
    value = getattr(msdlab, name)
    assert value.__name__ == name and name in dir(msdlab)


def test_a_submodule_is_there_when_used_and_a_wrong_name_is_an_attribute_error():
    assert msdlab.analysis.max_stable_dt is msdlab.max_stable_dt
    with pytest.raises(AttributeError, match="has no attribute 'Bodies'"):
        msdlab.Bodies  # noqa: B018
