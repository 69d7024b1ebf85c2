"""The templates are incomplete: every graded check fails on them, each with NotImplementedError."""

from __future__ import annotations

import subprocess
import sys

from msdlab.course import PROJECT_ROOT
from msdlab.course.report import CheckReport

CHECKS = PROJECT_ROOT / "tests" / "tasks"


def collected_checks() -> set[str]:
    process = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            str(CHECKS),
            "--collect-only",
            "-q",
            "-p",
            "no:cacheprovider",
        ],
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    return {line for line in process.stdout.splitlines() if "::" in line}


def test_every_graded_check_fails_on_the_templates_with_not_implemented(tmp_path):
    report_path = tmp_path / "report.json"
    process = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            str(CHECKS),
            "--impl=assignments",
            f"--msdlab-report={report_path}",
            "-q",
            "--tb=no",
            "-p",
            "no:cacheprovider",
            "-p",
            "no:nbval",
        ],
        cwd=PROJECT_ROOT,
        capture_output=True,
        text=True,
    )
    assert process.returncode == 1, process.stdout + process.stderr
    report = CheckReport.read(report_path)
    assert {check.nodeid for check in report.checks} == collected_checks(), (
        "every test in tests/tasks must be a graded check (a task marker and points)"
    )
    assert report.tasks() == [1, 2, 3, 4, 5]
    assert any(check.hidden for check in report.checks)
    not_stubbed = [
        f"{check.nodeid}: {check.outcome} {check.exception} {check.message[:80]}"
        for check in report.checks
        if check.outcome != "failed" or check.exception != "NotImplementedError"
    ]
    assert not not_stubbed, "checks that do not fail on a template stub:\n" + "\n".join(not_stubbed)
    for check in report.checks:
        assert check.message.startswith(f"Task {check.task}: "), check.message
    assert report.earned == 0
