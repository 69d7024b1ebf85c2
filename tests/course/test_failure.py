"""A failure in the course's words: the student's file and line, the input that failed."""

from pathlib import Path

import pytest

from msdlab.course import failure, report


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


def test_an_error_in_the_given_code_names_the_students_line_that_called_it(tmp_path):
    """A task file's given code raising on what the student's function handed it: the
    student's call is named, not the line of the given code."""
    folder = tmp_path / "assignments"
    folder.mkdir()
    bar = "# " + "-" * 75
    (folder / "task3.py").write_text(
        f"{bar} given code\ndef checked(axis):\n    raise ValueError('not a 3-vector')\n\n\n"
        f"{bar} your answers\ndef turn(angle, axis):\n    return checked(angle)\n"
    )
    namespace: dict = {}
    exec(compile((folder / "task3.py").read_text(), str(folder / "task3.py"), "exec"), namespace)
    with pytest.raises(ValueError) as raised:
        namespace["turn"](30.0, (0, 0, 1))
    assert failure.raised_in(raised.value, folder) == (
        "in your code: assignments/task3.py, line 8, in turn\n    return checked(angle)"
    )
    with pytest.raises(ValueError) as raised:  # called by a check: the given code's line
        namespace["checked"](30.0)
    assert "line 3, in checked" in failure.raised_in(raised.value, folder)


def test_a_given_check_of_arguments_names_the_line_that_passed_them(tmp_path):
    """A function of the student's answers whose first line is the given check of its
    arguments (``_checked_axis``): an argument it refuses is the fault of the student's line
    that called the function with it, as Python reports a wrong number of arguments."""
    folder = tmp_path / "assignments"
    folder.mkdir()
    bar = "# " + "-" * 75
    (folder / "task3.py").write_text(
        f"{bar} given code\ndef _checked_axis(axis):\n    raise ValueError('the angle?')\n\n\n"
        f"{bar} your answers\ndef matrix(angle, axis):\n    axis = _checked_axis(axis)\n\n\n"
        "def turn(angle, axis):\n    return matrix(axis, angle)  # the order swapped\n"
    )
    namespace: dict = {}
    exec(compile((folder / "task3.py").read_text(), str(folder / "task3.py"), "exec"), namespace)
    with pytest.raises(ValueError) as raised:
        namespace["turn"](30.0, (0, 0, 1))
    assert failure.raised_in(raised.value, folder).startswith(
        "in your code: assignments/task3.py, line 12, in turn\n    return matrix(axis, angle)"
    )
    with pytest.raises(ValueError) as raised:  # called by a check: the function's own line
        namespace["matrix"](30.0, 30.0)
    assert "line 8, in matrix" in failure.raised_in(raised.value, folder)


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


def test_a_tuple_over_several_lines_is_one_input():
    """Hypothesis writes a tuple whose parts may vary on lines of their own, each with its
    comment; the student reads the tuple."""
    note = (
        "Failing test case: f(\n    # The test always failed when commented parts were varied "
        "together.\n    shape=(\n        1,  # or any other generated value\n        1,  # or "
        "any other generated value\n        2,\n    ),\n    spacing=1.0,  # or any other "
        "generated value\n)"
    )
    assert (
        failure.failing_inputs(note) == "the inputs that failed: shape = (1, 1, 2), spacing = 1.0"
    )


def test_the_line_of_a_sandboxed_task_file_that_raised(serve_task):
    """Run in the grader's sandbox, an error names the line of the submission as a check run
    in one process does (the file by its name in the submission), and a to-do its function
    without the code."""
    remote = serve_task(
        "task5.py",
        """\
        class DampedVerlet:
            def __init__(self, damping):
                raise NotImplementedError("Task 5: store the damping.")

        def push(x):
            return x + [1, 2]
        """,
    )
    with pytest.raises(NotImplementedError) as to_do:
        remote.task(5).DampedVerlet(0.1)
    assert str(to_do.value).endswith("\nin your code: task5.py, line 3, in DampedVerlet.__init__")
    assert report.to_do(str(to_do.value)) == (
        "to do in task5.py, DampedVerlet.__init__: store the damping."
    )
    with pytest.raises(TypeError) as error:
        remote.task(5).push(None)
    assert str(error.value).endswith(
        "\nin your code: task5.py, line 6, in push\n    return x + [1, 2]"
    )


def test_an_error_in_sandboxed_given_code_names_the_students_line(serve_task):
    """In the grader's sandbox too, an error raised in the given code names the student's
    line that called it."""
    bar = "# " + "-" * 75
    remote = serve_task(
        "task3.py",
        f"""\
        {bar} given code
        def checked(axis):
            raise ValueError("not a 3-vector")


        {bar} your answers
        def turn(angle, axis):
            return checked(angle)
        """,
    )
    with pytest.raises(ValueError) as error:
        remote.task(3).turn(30.0, (0, 0, 1))
    assert str(error.value).endswith(
        "\nin your code: task3.py, line 8, in turn\n    return checked(angle)"
    )
