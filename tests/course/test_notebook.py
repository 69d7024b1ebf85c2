"""The notebooks' helper: which task files, unfinished work explained, edits picked up, checks."""

import os
import shutil
import sys
import time
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course.loader import SubmissionError
from msdlab.course.notebook import Course

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def course_folder(tmp_path: Path) -> Path:
    """A course folder with both implementations, as an instructor's checkout."""
    for name in ("solutions", "assignments"):
        shutil.copytree(ROOT / name, tmp_path / name)
    (tmp_path / "notebooks").mkdir()
    return tmp_path


def test_the_students_files_by_default_the_reference_answers_when_asked(course_folder, monkeypatch):
    monkeypatch.delenv("MSDLAB_IMPL", raising=False)
    start = course_folder / "notebooks"
    assert Course(start=start).label == "assignments"  # even beside solutions/
    assert Course(start=start).folder == (course_folder / "assignments").resolve()
    monkeypatch.setenv("MSDLAB_IMPL", "solutions")
    asked = Course(start=start)
    assert asked.folder == (course_folder / "solutions").resolve()
    assert asked.label == "solutions (the reference answers, not your task files)"
    assert Course("assignments", start=start).label == "assignments"  # the argument comes first


def test_an_unwritten_function_says_what_to_do_and_the_cell_ends_quietly(course_folder, capsys):
    course = Course("assignments", start=course_folder)
    task2 = course.task(2)
    with course.attempt():
        task2.spring_acceleration(task2.initial_grid((2, 2, 2)), 0.1, 0.5)
        pytest.fail("the template should have raised")
    out = capsys.readouterr().out
    assert "Task 2 is not finished: spring_acceleration (assignments/task2.py)" in out
    assert "to do: sum eq. (1.2)" in out and "msdlab check 2" in out
    assert len(out.splitlines()) <= 6  # a note, not a traceback wall
    assert course.unfinished == {2: "spring_acceleration (assignments/task2.py)"}


def test_the_note_is_said_once_per_function_and_the_cells_figures_are_closed(course_folder, capsys):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    course = Course("assignments", start=course_folder)
    task2 = course.task(2)
    before = plt.get_fignums()  # figures an earlier test in this process left open
    kept = plt.figure()
    for _ in range(2):
        with course.attempt():
            plt.subplots()  # a plot the unfinished function would have filled
            task2.spring_acceleration(task2.initial_grid((2, 2, 2)), 0.1, 0.5)
    notes = capsys.readouterr().out.splitlines()
    assert notes[-1] == (
        "Task 2 is not finished: spring_acceleration (assignments/task2.py) is still to write "
        "(see above)."
    )
    assert plt.get_fignums() == [*before, kept.number]
    plt.close(kept)


@pytest.mark.skipif(sys.version_info < (3, 11), reason="co_qualname is new in Python 3.11")
def test_a_method_is_named_with_its_class(course_folder, capsys):
    course = Course("assignments", start=course_folder)
    with course.attempt():
        course.task(5).DampedVerlet(0.1)
    assert "DampedVerlet.__init__ (assignments/task5.py)" in capsys.readouterr().out


def test_later_cells_that_miss_a_result_say_why(course_folder, capsys):
    course = Course("assignments", start=course_folder)
    cells = [  # two notebook cells, run in one namespace as a kernel does
        "with course.attempt():\n    a = task2.spring_acceleration(task2.initial_grid(), 1, 1)",
        "with course.attempt():\n    print(a)",
    ]
    namespace = {"course": course, "task2": course.task(2)}
    for cell in cells:
        exec(cell, namespace)
    out = capsys.readouterr().out
    assert "skipped: name 'a' is not defined" in out
    assert "spring_acceleration (assignments/task2.py)" in out.splitlines()[-1]


def test_other_errors_are_raised_as_usual(course_folder):
    course = Course("solutions", start=course_folder)
    with pytest.raises(NameError), course.attempt():  # nothing unfinished: a real typo
        undefined_name  # noqa: B018, F821
    with pytest.raises(NotImplementedError), course.attempt():
        raise NotImplementedError("not a template's message")
    with pytest.raises(ValueError), course.attempt():
        course.task(5).DampedVerlet(1.5)


def test_a_task_file_that_does_not_import_is_reported(course_folder, capsys):
    (course_folder / "assignments" / "task3.py").write_text("def broken(:\n")
    course = Course("assignments", start=course_folder)
    with course.attempt():
        _ = course.task(3).rotation_matrix
    out = capsys.readouterr().out
    assert out.startswith("Task 3 cannot run: task3.py could not be imported (line 1)")
    assert 3 in course.unfinished


def test_an_edited_task_file_is_used_without_restarting(course_folder):
    course = Course("assignments", start=course_folder)
    task1 = course.task(1)
    with pytest.raises(NotImplementedError):
        task1.particle_count(3)
    path = course_folder / "assignments" / "task1.py"
    written = "\n\ndef particle_count(n: int = N) -> int:\n    return n**3\n"
    path.write_text(path.read_text() + written)
    later = time.time() + 5  # a new modification time, whatever the file system's resolution
    os.utime(path, (later, later))
    assert task1.particle_count(3) == 27


def test_check_prints_what_the_command_prints(course_folder, capsys, monkeypatch):
    """The check cell shows the command's lines: the table, the hidden checks' worth and
    the messages in full."""
    shutil.copytree(ROOT / "tests" / "tasks", course_folder / "tests" / "tasks")
    report = Course("assignments", start=course_folder).check(1)
    cell = capsys.readouterr().out
    assert cell.startswith("checks of task 1 on assignments")
    assert report is not None and report.earned == 0 and report.tasks() == [1]
    assert "total: 0/" in cell and "hidden checks worth 6 more run when graded" in cell
    monkeypatch.chdir(course_folder)
    monkeypatch.setenv("COLUMNS", "100")
    assert main(["check", "1", "--impl", "assignments"]) == 1
    command = capsys.readouterr().out
    table = command.index("check ")
    assert cell[cell.index("check ") :] == command[table:]


def test_a_missing_folder_is_named(course_folder):
    with pytest.raises(SubmissionError, match="no folder of task files"):
        Course(str(course_folder / "elsewhere"), start=course_folder)
