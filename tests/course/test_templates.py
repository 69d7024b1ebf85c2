"""The template generator: solution blocks become NotImplementedError stubs, the rest stays."""

from __future__ import annotations

import shutil

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor.templates import TemplateError, differences, generate, make_template

SOLUTIONS = PROJECT_ROOT / "solutions"
ASSIGNMENTS = PROJECT_ROOT / "assignments"

SOLUTION = '''"""A task."""


def answer(n: int = 3) -> int:
    """The answer, eq. (1.1)."""
    check = int(n)
    ### BEGIN SOLUTION
    # TODO: return the cube of n.
    return check**3
    ### END SOLUTION


class Thing:
    """A thing."""

    def size(self) -> float:
        """Its size."""
        ### BEGIN SOLUTION
        # TODO: a very long explanation of what to do that goes on and on, telling the student
        #       which equation to use and which border cases to mind, until it no longer fits.
        return 1.0
        ### END SOLUTION
'''


def test_committed_templates_are_what_the_generator_makes():
    found = differences(SOLUTIONS, ASSIGNMENTS)
    assert not found, "stale templates (run 'msdlab templates'):\n" + "\n".join(map(str, found))


def test_solution_blocks_become_raises_with_their_todo():
    template = make_template(SOLUTION, 4)
    assert (
        '    check = int(n)\n    raise NotImplementedError("Task 4: return the cube of n.")\n'
        in (template)
    )
    assert "return check**3" not in template and "### BEGIN" not in template
    assert '"""The answer, eq. (1.1)."""' in template  # docstrings, signatures, given code stay
    assert "def answer(n: int = 3) -> int:" in template
    assert all(len(line) <= 100 for line in template.splitlines())
    namespace: dict = {}
    exec(compile(template, "template", "exec"), namespace)
    with pytest.raises(NotImplementedError, match=r"^Task 4: return the cube of n\.$"):
        namespace["answer"]()
    with pytest.raises(NotImplementedError) as raised:
        namespace["Thing"]().size()
    assert str(raised.value) == (
        "Task 4: a very long explanation of what to do that goes on and on, telling the student "
        "which equation to use and which border cases to mind, until it no longer fits."
    )


@pytest.mark.parametrize(
    ("source", "complaint"),
    [
        ("def f():\n    ### BEGIN SOLUTION\n    # TODO: x\n    return 1\n", "never closed"),
        ("def f():\n    return 1\n    ### END SOLUTION\n", "without ### BEGIN"),
        (
            "def f():\n    ### BEGIN SOLUTION\n    # TODO: x\n    ### BEGIN SOLUTION\n"
            "    ### END SOLUTION\n",
            "inside another",
        ),
        ("def f():\n    ### BEGIN SOLUTION\n    return 1\n    ### END SOLUTION\n", "TODO"),
        ("def f():\n    ### BEGIN SOLUTION\n    # TODO: x\n  ### END SOLUTION\n", "indentation"),
        ("def f():\n    return 1\n", "no ### BEGIN"),
        (
            "### BEGIN SOLUTION\n# TODO: x\ndef f():\n    return 1\n### END SOLUTION\n",
            "changes the interface of f",
        ),
    ],
)
def test_bad_solution_blocks_are_refused(source, complaint):
    with pytest.raises(TemplateError, match=complaint):
        make_template(source, 1, "task1.py")


def test_templates_command_writes_and_checks(tmp_path, capsys):
    solutions, out = tmp_path / "solutions", tmp_path / "assignments"
    shutil.copytree(SOLUTIONS, solutions)
    assert main(["templates", "--solutions", str(solutions), "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == [f"task{n}.py" for n in range(1, 6)]
    assert main(["templates", "--solutions", str(solutions), "--out", str(out), "--check"]) == 0
    (out / "task3.py").write_text("# edited by hand\n")
    (out / "task2.py").unlink()
    capsys.readouterr()
    assert main(["templates", "--solutions", str(solutions), "--out", str(out), "--check"]) == 1
    printed = capsys.readouterr().out
    assert "task2.py: missing" in printed and "task3.py: differs" in printed
    generate(solutions, out)
    assert not differences(solutions, out)
