"""``msdlab check``: the student's view of the checks (table, total, exit status)."""

from __future__ import annotations

import argparse
import importlib.util
import re
import shutil
import sys
import textwrap
import time
from pathlib import Path

import pytest

import msdlab
from msdlab.cli import main
from msdlab.commands import check
from msdlab.course import PROJECT_ROOT, manifest, runner
from msdlab.course.report import CheckReport

SOLUTIONS = PROJECT_ROOT / "solutions"
CHECKS = PROJECT_ROOT / "tests" / "tasks"


def test_all_checks_of_a_task_pass_on_the_solutions(capsys, tmp_path):
    report = tmp_path / "report.json"
    assert main(["check", "1", "--impl", str(SOLUTIONS), "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert "check" in out and "points" in out and "result" in out
    assert "task1 particle_count" in out and "total: 9/9 points, 5 of 5 checks passed" in out
    assert "(hidden)" not in out and "what the failing checks saw" not in out
    saved = CheckReport.read(report)
    assert saved.all_passed and saved.tasks() == [1] and not any(c.hidden for c in saved.checks)


@pytest.mark.parametrize(("chosen", "expected"), [(None, "numpy"), ("numba", "numba")])
def test_checks_run_on_the_graders_kernel_unless_chosen(chosen, expected, monkeypatch, tmp_path):
    """The grader's kernel (numpy) by default, so a check sees the numbers it sees when
    graded; a kernel the student chose with MSDLAB_KERNEL is kept."""
    if chosen is None:
        monkeypatch.delenv("MSDLAB_KERNEL", raising=False)
    else:
        monkeypatch.setenv("MSDLAB_KERNEL", chosen)
    probe = tmp_path / "checks"
    probe.mkdir()
    (probe / "test_probe.py").write_text(
        "import pytest\n\nimport msdlab as msd\n\n\n"
        "@pytest.mark.task1\n"
        "@pytest.mark.points(1)\n"
        "def test_kernel():\n"
        "    body = msd.Body.grid((2, 2), neighbours=(1,))\n"
        f"    assert msd.Simulation(body).dynamics.kernel == {expected!r}\n"
    )
    report, output = runner.run_checks(probe, SOLUTIONS)
    assert report.checks and all(check.passed for check in report.checks), output


def test_an_interrupted_run_of_the_checks_leaves_no_process_behind(monkeypatch, tmp_path):
    """A notebook's interrupt reaches the kernel only, not the checks' pytest process: the
    run ends that process before the interrupt goes on (it used to keep a CPU busy)."""
    shutil.copy(SOLUTIONS / "task1.py", tmp_path / "task1.py")
    with (tmp_path / "task1.py").open("a") as handle:
        handle.write("\ndef particle_count(n=N):\n    while True:\n        pass\n")
    started: list = []
    real = runner.subprocess.Popen
    monkeypatch.setattr(
        runner.subprocess, "Popen", lambda *a, **k: started.append(real(*a, **k)) or started[-1]
    )

    def interrupt(running: str | None) -> None:
        if running and "particle_count" in running:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        runner.run_checks(CHECKS, tmp_path, 1, call_timeout=600, progress=interrupt)
    assert started[0].poll() is not None


def test_pytests_own_output_has_no_warning_about_the_courses_config(capsys):
    """``msdlab check -v`` shows pytest's output: the course's pytest config (its
    ``timeout``) is understood by the plugins the checks run with."""
    assert main(["check", "1", "--impl", str(SOLUTIONS), "-v"]) == 0
    out = capsys.readouterr().out
    assert "passed" in out and "Unknown config option" not in out


def test_the_checks_leave_no_bytecode_in_the_course_and_msdlab_compiled(monkeypatch, tmp_path):
    """The next ``msdlab check`` loads msdlab's modules compiled (a second less to wait), and
    no ``__pycache__`` appears beside the task files or the checks."""
    monkeypatch.delenv("PYTHONDONTWRITEBYTECODE", raising=False)
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    tasks, checks = tmp_path / "tasks", tmp_path / "checks"
    shutil.copytree(SOLUTIONS, tasks, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(CHECKS, checks, ignore=shutil.ignore_patterns("__pycache__", "*hidden*"))
    compiled = Path(
        importlib.util.cache_from_source(
            str(Path(msdlab.__file__).parent / "engine" / "model" / "body.py")
        )
    )
    compiled.unlink(missing_ok=True)
    report, output = runner.run_checks(checks, tasks, 1)
    assert report.all_passed, output
    assert not [*tasks.rglob("__pycache__"), *checks.rglob("__pycache__")]
    assert compiled.is_file()


def test_templates_fail_with_what_to_do_each_said_once(capsys):
    assert main(["check", "task1", "--impl", "assignments"]) == 1
    out = capsys.readouterr().out
    assert re.search(r"task1 particle_count +0/1  FAILED  see \[1\]", out)
    # in full, once, with the file and the function to write
    assert out.count("to do in assignments/task1.py, particle_count: return the number of") == 1
    assert out.count("to do") == out.count("to do in assignments/task1.py, ") == 5
    assert "total: 0/9 points, 0 of 5 checks passed" in out
    assert "public 0 of 9 points; hidden checks worth 6 more run when graded" in out


def test_an_endless_loop_is_stopped_and_named(capsys, tmp_path):
    shutil.copy(SOLUTIONS / "task1.py", tmp_path / "task1.py")
    with (tmp_path / "task1.py").open("a") as handle:
        handle.write("\ndef particle_count(n=N):\n    while True:\n        pass\n")
    line = len((tmp_path / "task1.py").read_text().splitlines()) - 1
    assert main(["check", "1", "--impl", str(tmp_path), "--call-timeout", "0.5"]) == 1
    out = " ".join(capsys.readouterr().out.split())  # as wrapped to any terminal's width
    assert "task1.py: particle_count did not return within 0.5 s (check particle_count)" in out
    assert f"stopped in {tmp_path.name}/task1.py, line {line}, in particle_count" in out
    assert "total: 8/9 points" in out  # the other checks do not wait for it


SWALLOWING = """
def particle_count(n=N):
    while True:
        try:
            while True:
                pass
        except Exception:  # catches every stop that is an Exception, and goes on
            pass
"""


@pytest.mark.parametrize(
    ("limits", "said"),
    [(["--call-timeout", "0.5"], "particle_count did not return within 0.5 s"),
     (["--call-timeout", "600", "--task-timeout", "0.5"], "particle_count used up the 0.5 s")],
)  # fmt: skip
def test_code_that_catches_the_stop_and_goes_on_is_stopped_all_the_same(
    capsys, tmp_path, limits, said
):
    """A loop that catches what stops it (``except Exception``) is stopped again a moment
    later, by an exception it cannot catch, with what the first stop said."""
    shutil.copy(SOLUTIONS / "task1.py", tmp_path / "task1.py")
    with (tmp_path / "task1.py").open("a") as handle:
        handle.write(SWALLOWING)
    started = time.monotonic()
    assert main(["check", "1", "--impl", str(tmp_path), *limits]) == 1
    assert time.monotonic() - started < 60
    out = " ".join(capsys.readouterr().out.split())
    assert f"task1.py: {said}" in out and "StopIgnored" not in out
    assert f"{tmp_path.name}/task1.py, line " in out and "in particle_count" in out
    assert "total: 8/9 points" in out


def endless(tmp_path: Path, where: str) -> Path:
    """Task 2's answer with an endless loop at the top level of the file, or at the start of
    ``where`` (a function every check of task 2 calls); its line is the file's 'while'."""
    text = (SOLUTIONS / "task2.py").read_text()
    loop = "while len(str(N)) > 0:\n    N = N + 0\n"
    if where == "<module>":
        text = text.replace("\nDT = ", f"\n{loop}DT = ", 1)
    else:
        head = text.index(f"def {where}(")
        body = text.index('"""\n', text.index('"""', head) + 3) + 4
        text = (
            text[:body]
            + "    n = 1\n"
            + textwrap.indent(loop.replace("N", "n"), "    ")
            + text[body:]
        )
    (tmp_path / "task2.py").write_text(text)
    return tmp_path / "task2.py"


@pytest.mark.parametrize(
    ("where", "said"), [("<module>", "at the top level of the file"),
                        ("spring_acceleration", "in spring_acceleration")]
)  # fmt: skip
def test_a_loop_every_check_meets_is_stopped_once_where_it_was(capsys, tmp_path, where, said):
    """A loop at the top level of a task file, or in a function every check calls, costs one
    time limit, not one a check, and is named once, by its file, line and function."""
    path = endless(tmp_path, where)
    line = (
        path.read_text()
        .splitlines()
        .index(next(x for x in path.read_text().splitlines() if "while len(str(" in x))
        + 1
    )
    started = time.monotonic()
    assert main(["check", "2", "--impl", str(tmp_path), "--call-timeout", "1"]) == 1
    assert time.monotonic() - started < 30  # six checks, one limit: not 6 x 1 s of waiting
    out = " ".join(capsys.readouterr().out.split())
    assert out.count(f"{tmp_path.name}/task2.py, line {line}, {said}") == 1
    assert out.count("while len(str(") == 1
    assert out.count("did not return within") + out.count("was still being imported") == (
        1 if where == "<module>" else 2  # the message, then once for the later checks
    )


def test_the_processor_budget_stops_a_function_that_is_only_slow(capsys, tmp_path):
    """Calls each within the per-call limit that add up to more than a function's processor
    time in its task's checks: the check running then fails naming where the code was, its
    later calls are stopped at once, and another task's checks are not charged for them."""
    path = endless(tmp_path, "spring_acceleration")
    path.write_text(path.read_text().replace("while len(str(n)) > 0:", "while n < 2_000_000:"))
    path.write_text(path.read_text().replace("n = n + 0", "n = n + 1"))
    shutil.copy(SOLUTIONS / "task1.py", tmp_path / "task1.py")
    code = main(["check", "--impl", str(tmp_path), "--task-timeout", "0.2", "--call-timeout", "9"])
    out = " ".join(capsys.readouterr().out.split())
    assert code == 1 and "task1 steps_to_floor_as_template 2/2 pass" in out  # not charged
    used_up = "task2.py: spring_acceleration used up the 0.2 s of processor time it may take"
    assert out.count(used_up) == 1
    assert f"{tmp_path.name}/task2.py, line " in out and ", in spring_acceleration" in out
    assert "had used up its processor time in task 2's checks in check " in out


def test_the_checks_say_what_runs_while_they_run(capsys):
    """Never silent: a line as each task's checks start (on a terminal, one line names each
    check as it runs)."""
    assert main(["check", "1", "--impl", str(SOLUTIONS)]) == 0
    out = capsys.readouterr().out
    assert out.index("  task 1...") < out.index("total: 9/9 points")


def test_a_syntax_error_is_reported_once(capsys, tmp_path):
    (tmp_path / "task1.py").write_text("def particle_count(n:\n")
    assert main(["check", "1", "--impl", str(tmp_path)]) == 1
    out = capsys.readouterr().out
    assert "task1 (all 5 checks)" in out and out.count("SyntaxError") == 1


def test_missing_test_tools_name_the_install_command(capsys, monkeypatch):
    monkeypatch.setattr(check, "missing_test_tools", lambda: ["pytest"])
    assert main(["check", "1"]) == 2
    out = capsys.readouterr().out
    assert "needs pytest" in out and f"{sys.executable} -m pip install -e " in out
    assert "[grade]" in out


def test_without_hidden_files_hidden_is_refused_and_the_manifest_counts_them(capsys, tmp_path):
    """A release has no hidden checks: --hidden would do nothing there, so it is refused
    with why; the last line still says what the hidden checks are worth."""
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(CHECKS / name, checks)
    manifest.write(checks / manifest.FILE_NAME, [(1, 9, False), (1, 5, True), (2, 7, True)])
    assert main(["check", "1", "--hidden", "--checks", str(checks), "--impl", "solutions"]) == 2
    assert "the hidden checks are not in this copy of the course" in capsys.readouterr().out
    assert main(["check", "1", "--checks", str(checks), "--impl", "solutions"]) == 0
    assert "public 9 of 9 points; hidden checks worth 5 more run when graded" in (
        capsys.readouterr().out
    )


def test_a_release_does_not_offer_hidden(monkeypatch):
    """Where msdlab's checks folder holds no hidden checks (a student's release), ``msdlab
    check --help`` does not list --hidden."""
    monkeypatch.setattr(check, "has_hidden_checks", lambda folder: False)
    parser = argparse.ArgumentParser(prog="msdlab")
    check.register(parser.add_subparsers())
    helped = parser._subparsers._group_actions[0].choices["check"].format_help()
    assert "--task-timeout" in helped and "--hidden" not in helped


def test_default_is_the_students_assignments_folder(capsys, tmp_path, monkeypatch):
    (tmp_path / "assignments").mkdir()
    shutil.copy(SOLUTIONS / "task1.py", tmp_path / "assignments" / "task1.py")
    monkeypatch.chdir(tmp_path)
    assert main(["check", "1", "--hidden"]) == 0
    out = capsys.readouterr().out
    assert str(tmp_path / "assignments") in out
    assert "(hidden)" in out and "total: 15/15 points" in out
    assert "public 9 of 9 points; hidden 6 of 6 points" in out


def test_the_reference_answers_only_when_asked_and_then_said(capsys, tmp_path, monkeypatch):
    for name in ("assignments", "solutions"):
        (tmp_path / name).mkdir()
        shutil.copy(PROJECT_ROOT / name / "task1.py", tmp_path / name / "task1.py")
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("MSDLAB_IMPL", raising=False)
    assert main(["check", "1"]) == 1  # the templates, though solutions/ is here
    out = capsys.readouterr().out
    assert str(tmp_path / "assignments") in out and "reference answers" not in out
    monkeypatch.setenv("MSDLAB_IMPL", "solutions")
    assert main(["check", "1"]) == 0
    out = capsys.readouterr().out
    assert str(tmp_path / "solutions") in out
    assert "the reference answers, not your task files" in out


def test_an_error_in_the_students_code_names_its_file_and_line(capsys, tmp_path):
    """Without -v: the file, line, function and code of the task file that raised; the
    property check's failing input said plainly, none of Hypothesis' own wording."""
    (tmp_path / "assignments").mkdir()
    answer = (SOLUTIONS / "task2.py").read_text()
    broken = "        a[first] += f[..., :2]  # one coordinate short\n"
    answer = answer.replace("        a[first] += f\n", broken)
    (tmp_path / "assignments" / "task2.py").write_text(answer)
    line = answer.splitlines().index(broken.rstrip("\n")) + 1
    assert main(["check", "2", "--impl", str(tmp_path / "assignments")]) == 1
    out = capsys.readouterr().out
    assert f"in your code: assignments/task2.py, line {line}, in spring_acceleration" in out
    assert "a[first] += f[..., :2]  # one coordinate short" in out
    assert "it fails whatever the input (tried first: seed = " in " ".join(out.split())  # wrapped
    for hypothesis_words in ("Failing test case", "Falsifying example", "generated value", "@seed"):
        assert hypothesis_words not in out


@pytest.mark.parametrize(
    ("args", "complaint"),
    [
        (["check", "7"], "TASK must be one of 1, 2, 3, 4, 5"),
        (["check", "1", "--impl", "/no/such/folder"], "no folder of task files"),
        (["check", "1", "--checks", "/no/such/checks"], "no checks folder"),
    ],
)
def test_bad_arguments_exit_2(capsys, args, complaint):
    assert main(args) == 2
    assert complaint in capsys.readouterr().err
