"""A failure in the course's words: the student's file and line, the input that failed."""

from pathlib import Path

from msdlab.course import failure


def raising_task_file(folder: Path) -> BaseException:
    folder.mkdir()
    (folder / "task2.py").write_text("def push(x):\n    return x + [1, 2]\n")
    namespace: dict = {}
    exec(compile((folder / "task2.py").read_text(), str(folder / "task2.py"), "exec"), namespace)
    try:
        namespace["push"](__import__("numpy").zeros(3))
    except ValueError as error:
        return error
    raise AssertionError("the task file should have raised")


def test_the_line_of_the_task_file_that_raised(tmp_path):
    error = raising_task_file(tmp_path / "assignments")
    assert failure.raised_in(error, tmp_path / "assignments") == (
        "in your code: assignments/task2.py, line 2, in push\n    return x + [1, 2]"
    )
    assert failure.raised_in(error, tmp_path / "elsewhere") == ""
    assert failure.raised_in(error, None) == ""


def test_the_failing_input_plainly():
    note = (
        "Falsifying example: test_rotation(\n    task2=<task module /a/task2.py>,\n"
        "    seed=12,\n    angle=0.5,\n)"
    )
    assert failure.failing_inputs(note) == "the inputs that failed: seed = 12, angle = 0.5"
    every = (
        "Failing test case: test_rotation(\n    task2=<task module /a/task2.py>,\n"
        "    seed=0,  # or any other generated value\n)"
    )
    assert failure.failing_inputs(every) == "it fails whatever the input (tried first: seed = 0)"
    assert failure.failing_inputs("You can add @seed(1) to this test") == ""
