"""`msdlab validate`: the solutions pass, the templates fail, and the mutants of the solution
blocks are killed by checks named in the report (a small sample here; all of them take long)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor import validate

SOURCE = textwrap.dedent(
    '''
    def given(x):
        return x - 1


    def answer(x, y):
        """Docs."""
        ### BEGIN SOLUTION
        if x < y:
            return -x + 2 * y
        ### END SOLUTION
        return 0
    '''
)


def test_mutants_change_only_the_solution_blocks_one_thing_at_a_time():
    found = validate.mutants(SOURCE, 1)
    labels = {m.label for m in found}
    assert {
        "line 9: x < y -> x <= y",  # a changed comparison
        "line 10: -x + 2 * y -> -x - 2 * y",  # a swapped operator
        "line 10: -x -> x",  # a sign flip
        "line 10: 2 -> 3",  # an off-by-one constant
        "line 10: -x + 2 * y -> -x",  # a dropped term
    } <= labels
    assert all(m.line in (9, 10) for m in found)  # `given` and `return 0` stay as they are
    for mutant in found:
        changed = [a for a, b in zip(SOURCE.splitlines(), mutant.source.splitlines()) if a != b]
        assert len(changed) == 1
        compile(mutant.source, "mutant", "exec")


def test_the_same_text_twice_on_a_line_gives_mutants_told_apart():
    source = "def f(x):\n    ### BEGIN SOLUTION\n    return x[0] - x[0]\n    ### END SOLUTION\n"
    found = validate.mutants(source, 1)
    labels = [m.label for m in found]
    assert len(labels) == len(set(labels))  # one label per mutant: none hides another's outcome
    assert {
        "line 3: 0 -> 1 (1st of 2 on the line)",
        "line 3: 0 -> 1 (2nd of 2 on the line)",
    } <= set(labels)
    (second,) = [m for m in found if m.label == "line 3: 0 -> 1 (2nd of 2 on the line)"]
    assert second.source.splitlines()[2].strip() == "return x[0] - x[1]"
    assert second.claims()[0] == "f: 0 -> 1 (2nd of 2 on the line)"


def test_validate_reports_solution_template_and_kills(capsys):
    reports = validate.validate(PROJECT_ROOT, [5], sample=4, seed=1)
    (report,) = reports
    assert not report.solution_failures and not report.template_passes
    assert report.mutants == 4 and len(report.kills) == 4
    text = validate.format_report(reports, verbose=True)
    assert "solution: all pass" in text and "template: all fail" in text
    assert "kill rate:" in text and "mutants killed per check (alone:" in text
    assert report.trivial_paid and not any(report.trivial_paid.values())
    assert "every check fails, 0 points" in text


def test_the_report_names_lone_kills_and_survivors_with_their_reasons(tmp_path):
    report = validate.TaskReport(1, ["a", "b"], mutants=4)
    report.kills = {"m1": ["a"], "m2": ["a", "b"], "m3": [], "m4": []}
    (tmp_path / validate.EQUIVALENT_FILE).write_text(
        '{"task1": {"answer: x < y -> x <= y": "x == y never reaches it"}}'
    )
    reasons = validate.equivalence_reasons(tmp_path / validate.EQUIVALENT_FILE, 1)
    (mutant,) = [m for m in validate.mutants(SOURCE, 1) if m.label == "line 9: x < y -> x <= y"]
    assert mutant.claims()[0] in reasons
    report.equivalent = {"m3": reasons[mutant.claims()[0]]}
    assert report.alone("a") == ["m1"] and report.unexplained == ["m4"]
    assert report.kill_rate == pytest.approx(2 / 3)
    text = validate.format_report([report])
    assert "alone: m1" in text and "m3: x == y never reaches it" in text
    assert "survivors no check catches (1):\n    m4" in text
    report.trivial_paid = {"zeros": ["b"]}
    assert validate.broken(report) and "PAID zeros by b" in validate.format_report([report])


def test_validate_command_refuses_an_unknown_task(capsys):
    assert main(["validate", "7"]) != 0
    assert "no task 7" in capsys.readouterr().err


def test_the_checks_run_without_hypothesis_deadlines():
    """A check's own ``@settings(max_examples=…)`` keeps validation's profile, also outside
    pytest (``msdlab validate``): a mutant slow on a loaded machine fails its check, not
    hypothesis's 200 ms deadline."""
    folder = str(PROJECT_ROOT / "tests" / "tasks")
    deadlines = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(f"""
            from msdlab.instructor import validate
            for task in (1, 2, 3):
                for check in validate.collect_checks({folder!r}, task):
                    if hasattr(check.function, "hypothesis"):
                        print(check.name, check.function._hypothesis_internal_use_settings.deadline)
            """)],
        capture_output=True, text=True, check=True,
    ).stdout.splitlines()  # fmt: skip
    assert len(deadlines) >= 3 and all(line.endswith(" None") for line in deadlines), deadlines
