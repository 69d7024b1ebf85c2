"""No points for delegating: while a task is checked, the engine's answer to it refuses the
submission's calls, and only the submission's."""

from __future__ import annotations

import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import msdlab as msd
from msdlab.course import PROJECT_ROOT, delegation
from msdlab.course.loader import FolderImplementation
from msdlab.course.report import CheckReport

SUBMISSION = """
import numpy as np
import msdlab as msd
from msdlab.engine.backends.numpy import spring_forces

class Subclassed(msd.Verlet):
    pass

def engine_step(x, v, dt, dynamics):
    return msd.Verlet().step(x, v, dt, dynamics)

def engine_rotation():
    return msd.rotation_matrix(30.0, (0.0, 0.0, 1.0))

def imported_kernel(body, x):
    return spring_forces(body, x)

def own_rotation():
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
"""


@pytest.fixture(scope="module")
def student(tmp_path_factory):
    delegation.install()
    folder = tmp_path_factory.mktemp("delegating")
    (folder / "task5.py").write_text(textwrap.dedent(SUBMISSION))
    return folder, FolderImplementation(folder).task(5)


def free_particle():
    body = msd.Body.from_arrays([[0.0, 1.0, 0.0]])
    return msd.Dynamics(body), np.zeros((1, 3)), np.ones((1, 3))


def test_calling_or_subclassing_the_answer_is_refused_naming_the_task(student):
    folder, module = student
    dynamics, x, v = free_particle()
    with delegation.refusing(5, folder):
        with pytest.raises(delegation.DelegationRefused, match="task 5 asks for your own"):
            module.engine_step(x, v, 0.1, dynamics)
        with pytest.raises(delegation.DelegationRefused, match=r"msdlab\.Verlet"):
            module.Subclassed(0.1)
    with delegation.refusing(3, folder):
        with pytest.raises(delegation.DelegationRefused, match="rotation_matrix"):
            module.engine_rotation()
        body = msd.Body.from_arrays([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[0, 1]])
        with pytest.raises(delegation.DelegationRefused, match="spring_forces"):
            module.imported_kernel(body, body.positions)


def test_other_tasks_own_code_and_the_judge_are_not_refused(student):
    folder, module = student
    dynamics, x, v = free_particle()
    with delegation.refusing(3, folder):
        module.engine_step(x, v, 0.1, dynamics)  # the engine's Verlet is no answer to task 3
        np.testing.assert_allclose(module.own_rotation(), msd.rotation_matrix(30.0, (0, 0, 1)))
    with delegation.refusing(5, folder):
        msd.Verlet(0.1).step(x, v, 0.1, dynamics)  # the checks' own oracles keep working
    module.Subclassed(0.1)  # outside a check nothing is refused


def test_an_instructor_can_allow_delegation_per_task(tmp_path):
    folder = tmp_path / "delegating"
    shutil.copytree(PROJECT_ROOT / "solutions", folder)
    task3 = folder / "task3.py"
    solution = "rotation = rotation_matrix(angle_degrees, axis)"
    task3.write_text(
        task3.read_text().replace(solution, "rotation = msd.rotation_matrix(angle_degrees, axis)")
    )

    def lost(*options: str) -> list[str]:
        report = tmp_path / "report.json"
        command = [
            sys.executable, "-m", "pytest", str(PROJECT_ROOT / "tests" / "tasks"), "-q",
            "-m", "task3 and not hidden", "-k", "rotate_layout", f"--impl={folder}",
            f"--msdlab-report={report}", "-p", "no:cacheprovider", *options,
        ]  # fmt: skip
        subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, check=False, timeout=300)
        return [c.exception for c in CheckReport.read(report).checks if not c.passed]

    assert lost() == ["DelegationRefused"]
    assert lost("--allow-delegation=3") == []
