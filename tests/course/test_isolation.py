"""`msdlab grade` isolates submissions by the operating system, as root and without root.

Hostile submissions are built on the templates, so every point they earned would be
unearned. Each one first disables the audit hook's deny lists (module globals of the
sandbox's child) and then works through shell commands the hook never sees.
"""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor.judging import sandbox, sandbox_child

CHECKS = PROJECT_ROOT / "tests" / "tasks"
MARKER = "msdlab-hostile-helper"
UNPRIVILEGED = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", "--"]

needs_bubblewrap = pytest.mark.skipif(
    sandbox.isolation_problem() is not None,
    reason=f"the namespace sandbox cannot start here: {sandbox.isolation_problem()}",
)

UNHOOK = """
import __main__, subprocess
for name in ("_BLOCKED", "_WRITES", "_LISTS"):
    getattr(__main__, name, set()).clear()  # the audit hook's deny lists, emptied
"""


def saboteur(csv_path: Path, feedback: Path) -> str:
    """Plants modules on sys.path, fills /tmp, and leaves a detached helper that kills
    everything it can and rewrites the grades."""
    script = f"""
    # {MARKER}
    for d in {" ".join(sys.path[1:4])} /sandbox/lib /submission /tmp; do
        echo 'raise SystemExit' > "$d/numpy.py"; echo 'raise SystemExit' > "$d/sitecustomize.py"
    done
    head -c 300000000 /dev/zero > /tmp/fill
    while :; do
        kill -9 -1; echo ha""cked > {csv_path}
        echo ha""cked > {feedback}/students/saboteur.md; sleep 0.2
    done
    """
    return (
        UNHOOK + f"subprocess.Popen(['/bin/sh', '-c', {script!r}], start_new_session=True, "
        "stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n"
    )


def thief(root: Path) -> str:
    """task2 copied from wherever it can be read: the solutions and the git history of
    the course at ``root``, other submissions through /proc and the grader's temporary
    folder."""
    return (
        UNHOOK
        + f'''
def spring_acceleration(x, spacing, stiffness):
    import subprocess
    commands = [
        "cat {root}/solutions/task2.py",
        "git -C {root} show HEAD:solutions/task2.py",
        "cat /proc/*/root/submission/task2.py /proc/*/cwd/submission/task2.py",
        "cat {tempfile.gettempdir()}/msdlab-grade-*/submission/task2.py",
    ]
    for command in commands:
        found = subprocess.run(["/bin/sh", "-c", command], capture_output=True, text=True)
        source = found.stdout
        if "def spring_acceleration" in source and "{MARKER}" not in source:
            namespace = {{}}
            exec(source, namespace)
            return namespace["spring_acceleration"](x, spacing, stiffness)
    raise NotImplementedError("{MARKER}: nothing to copy")
'''
    )


def hostile_processes() -> list[str]:
    """Command lines of hostile helpers still running anywhere on the machine."""
    found = []
    for cmdline in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            text = cmdline.read_bytes().decode(errors="replace")
        except OSError:
            continue
        if MARKER in text and "pytest" not in text:
            found.append(text)
    return found


@needs_bubblewrap
@pytest.mark.skipif(os.geteuid() != 0, reason="grading as root and as user 65534 needs root")
@pytest.mark.parametrize("grader", ["root", "unprivileged"])
def test_hostile_submissions_earn_nothing_and_leave_nothing(grader):
    command = UNPRIVILEGED if grader == "unprivileged" else []
    root = Path(tempfile.mkdtemp(prefix="msdlab-isolation-"))
    environment = dict(os.environ, TMPDIR=str(root), HOME=str(root))
    project = PROJECT_ROOT
    if grader == "unprivileged":  # the grader's user reads the course: a readable copy of it
        root.chmod(0o755)
        project = root / "course"
        for part in ("msdlab", "solutions", "assignments"):
            shutil.copytree(PROJECT_ROOT / part, project / part)
        environment["PYTHONPATH"] = str(project)
        code = "import os, sys; os.stat(os.path.realpath(sys.executable)); import msdlab"
        probe = subprocess.run([*command, sys.executable, "-c", code], env=environment, cwd=root)
        if probe.returncode != 0:
            shutil.rmtree(root, ignore_errors=True)
            pytest.skip("user 65534 cannot run this Python environment (a folder is private)")
    try:
        checks = root / "checks"
        checks.mkdir()
        for name in ("conftest.py", "test_task2.py"):
            shutil.copy(CHECKS / name, checks)
        out, feedback = root / "out" / "grades.csv", root / "out" / "feedback"
        folders = {"honest": project / "solutions", "saboteur": None, "thief": None}
        for name in folders:
            source = folders[name] or project / "assignments"
            folders[name] = shutil.copytree(source, root / name)
        sabotaged, stolen = folders["saboteur"] / "task2.py", folders["thief"] / "task2.py"
        sabotaged.write_text(sabotaged.read_text() + saboteur(out, feedback))
        stolen.write_text(stolen.read_text() + thief(project))
        if grader == "unprivileged":
            shutil.chown(root, 65534, 65534)
            for path in root.rglob("*"):
                shutil.chown(path, 65534, 65534)
        arguments = [sys.executable, "-m", "msdlab", "grade", *map(str, folders.values())]
        arguments += ["--out", str(out), "--feedback", str(feedback), "--checks", str(checks)]
        arguments += ["--jobs", "2", "--call-timeout", "5", "--timeout", "120"]
        finished = subprocess.run(
            [*command, *arguments],
            env=environment,
            cwd=root,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert out.is_file(), finished.stderr
        written = out.read_bytes()
        time.sleep(1.0)  # a helper that outlived the run would rewrite the grades by now
        assert out.read_bytes() == written and "hacked" not in written.decode()
        assert hostile_processes() == []
        assert finished.returncode == 0, finished.stderr
        rows = {row["id"]: row for row in csv.DictReader(out.open())}
        assert rows["saboteur"]["total"] == rows["thief"]["total"] == "0", rows
        honest = (feedback / "students" / "honest.md").read_text()
        assert f"**{rows['honest']['total']} of {rows['honest']['total']} points**" in honest
        assert int(rows["honest"]["total"]) > 0 and rows["honest"]["notes"] == ""
        planted = [p for d in sys.path[1:4] for p in Path(d).glob("numpy.py")]
        assert planted == []
        assert not any("hacked" in path.read_text() for path in feedback.rglob("*.md"))
    finally:
        shutil.rmtree(root, ignore_errors=True)


@needs_bubblewrap
def test_a_python_environment_under_tmp_stays_visible_in_the_sandbox(tmp_path):
    """The private /tmp is mounted first, the environment on top: a venv made in /tmp
    (as CI makes its own) still runs inside the sandbox."""
    base = Path(tempfile.mkdtemp(dir="/tmp"))
    try:
        subprocess.run(
            [sys.executable, "-m", "venv", "--without-pip", str(base / "venv")], check=True
        )
        sites = [str(PROJECT_ROOT), *sys.path[1:]]
        code = (
            f"import sys; sys.path[:0] = {sites!r}; from msdlab.instructor.judging import sandbox; "
            "print(sandbox.isolation_problem())"
        )
        result = subprocess.run(
            [str(base / "venv" / "bin" / "python"), "-c", code],
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        assert result.stdout.strip() == "None", result.stdout + result.stderr
    finally:
        shutil.rmtree(base, ignore_errors=True)


def test_an_unknown_isolation_level_is_refused():
    assert "unknown isolation" in sandbox.isolation_problem("none")
    with pytest.raises(ValueError, match="isolation must be one of"):
        sandbox.SandboxProcess(PROJECT_ROOT / "solutions", isolation="none")


@needs_bubblewrap
def test_a_sandbox_that_dies_before_its_first_answer_is_an_error_not_a_fallback():
    starved = sandbox.SandboxProcess(PROJECT_ROOT / "assignments", memory_bytes=2**20)
    try:
        with pytest.raises(sandbox.SandboxError, match="cannot start the grading sandbox"):
            starved.start()
        assert starved.strong and "namespaces" in starved.isolation
    finally:
        starved.cleanup()


def test_the_weaker_isolation_is_named_in_every_row_and_the_summary(tmp_path, capsys):
    nobody = tmp_path / "nobody"
    nobody.mkdir()
    shutil.copy(PROJECT_ROOT / "assignments" / "task1.py", nobody)
    checks = tmp_path / "checks"
    checks.mkdir()
    (checks / "test_nothing.py").write_text("def test_nothing():\n    pass\n")
    out = tmp_path / "grades.csv"
    arguments = ["grade", str(nobody), "--out", str(out), "--checks", str(checks)]
    assert main([*arguments, "--isolation", "process"]) == 0
    rows = {row["id"]: row for row in csv.DictReader(out.open())}
    assert "weaker isolation 'process'" in rows["nobody"]["notes"]
    assert "isolation: process" in capsys.readouterr().out


def test_the_engine_is_loaded_before_the_submission_runs(tmp_path):
    """Nothing a submission's calls need is read once its code has run: the process sandbox's
    guard refuses files outside its roots, and the submission may have changed how its
    process imports."""
    (tmp_path / "task1.py").write_text(
        "import sys\n"
        "LOADED = sorted(name for name in sys.modules if name.startswith('msdlab'))\n"
        "def loaded():\n"
        "    return LOADED\n"
    )
    remote = sandbox.RemoteImplementation(tmp_path, isolation="process", timeout=60.0)
    try:
        loaded = set(remote.task(1).loaded())
    finally:
        remote.close()
    engine = set(sandbox_child.engine_modules())
    assert {
        "msdlab.engine.simulation.simulation",
        "msdlab.analysis",
        "msdlab.interaction.contact",
    } <= engine
    assert not {name for name in engine if name.startswith("msdlab.instructor")}
    assert engine - loaded == set()
