"""Process-wide settings are made by msdlab's own processes (the command line, a course
notebook's ``Course()``), never by importing msdlab."""

from __future__ import annotations

import os
import platform
import subprocess
import sys

import pytest

from msdlab import cli
from msdlab.engine.backends import process

SETTINGS = ("OMP_WAIT_POLICY", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_")

# A step of an integrator written with numpy arrays, as a page-fault count: temporaries of
# a body's positions made and freed the same way every step.
FAULTS_PER_STEP = """
import resource, numpy as np
{configure}
x = np.ones(({particles}, 3)); v = np.ones_like(x)
def step():
    old = x - v * 1e-3
    new = 2.0 * x - old + np.ones_like(x) * 1e-6
    return new, (new - x) / 1e-3
for _ in range(5):
    step()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(50):
    step()
print((resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before) / 50)
"""


def fresh_env() -> dict[str, str]:
    return {key: value for key, value in os.environ.items() if key not in SETTINGS}


def run(code: str) -> str:
    out = subprocess.run(
        [sys.executable, "-c", code], env=fresh_env(), capture_output=True, text=True, check=True
    )
    return out.stdout.strip()


def test_importing_msdlab_sets_nothing() -> None:
    code = "import os, msdlab, msdlab.engine.backends.numba\n"
    code += f"print([os.environ.get(k) for k in {SETTINGS!r}])"
    assert run(code) == str([None] * len(SETTINGS))


def test_the_command_line_sets_them_unless_the_user_did(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in SETTINGS:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(process, "keep_freed_memory", lambda: None)  # not in the test process
    cli.configure_process()
    assert os.environ["OMP_WAIT_POLICY"] == "PASSIVE"
    monkeypatch.setenv("OMP_WAIT_POLICY", "ACTIVE")
    cli.configure_process()
    assert os.environ["OMP_WAIT_POLICY"] == "ACTIVE"


def test_a_course_notebook_makes_them_as_the_command_line_does(tmp_path) -> None:
    """The task notebooks step big bodies on threads in a Jupyter kernel: on a busy machine
    a step of 18³ with 67 388 springs took 40 to 95 ms with spinning threads, 1 to 2 ms
    with sleeping ones (``benchmarks/busy_machine.py``)."""
    (tmp_path / "assignments").mkdir()
    code = "import os\nfrom msdlab.course.notebook import Course\n"
    code += f"Course(start=__import__('pathlib').Path({str(tmp_path)!r}))\n"
    code += "print(os.environ.get('OMP_WAIT_POLICY'))"
    assert run(code) == "PASSIVE"


@pytest.mark.skipif(platform.libc_ver()[0] != "glibc", reason="a glibc malloc setting")
@pytest.mark.parametrize("particles", [27_000, 216_000])  # 30³ and 60³: 0.6 and 5.2 MB
def test_freed_memory_is_kept_for_the_next_step(particles: int) -> None:
    """With `process.keep_freed_memory` the temporaries of a step reuse the memory of the
    last step's instead of faulting in fresh pages, and child processes inherit it."""
    configure = "from msdlab.engine.backends.process import keep_freed_memory\nkeep_freed_memory()"
    step = FAULTS_PER_STEP.format(configure=configure, particles=particles)
    assert float(run(step)) < 5
    child = FAULTS_PER_STEP.format(configure="", particles=particles)
    inherited = f"""{configure}
import subprocess, sys
print(subprocess.run([sys.executable, "-c", {child!r}], capture_output=True, text=True).stdout)
"""
    assert float(run(inherited)) < 5


def test_a_setting_of_the_user_is_kept() -> None:
    user_set = "import os; os.environ['MALLOC_TRIM_THRESHOLD_'] = '131072'\n"
    configure = "from msdlab.engine.backends import process\nprocess.keep_freed_memory()\n"
    assert run(user_set + configure + "print(os.environ.get('MALLOC_MMAP_THRESHOLD_'))") == "None"
