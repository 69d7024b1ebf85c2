"""What the course notebooks use: the task files under study, unfinished work, the checks.

::

    from msdlab.course.notebook import Course

    course = Course()  # the task files, chosen as the checks choose them
    task2 = course.task(2)  # imported again whenever the file changes
    with course.attempt():  # an unwritten function prints what to do, not a traceback
        a = task2.spring_acceleration(x, spacing, stiffness)
    course.check(2)  # the checks of task 2, with their messages

The task files are those of ``Course(spec)``, else of ``$MSDLAB_IMPL``, else the
student's ``assignments/`` (even in a checkout that holds ``solutions/``), as for
``pytest --impl`` and ``msdlab check``; `Course.label` says when they are the reference
answers. A course notebook is one of msdlab's own processes: ``Course()`` makes the
command line's process settings (`msdlab.engine.backends.process.configure_process`:
threads that wait sleep, so a big body's threaded step keeps its speed on a busy machine).
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
import textwrap
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import TracebackType
from typing import Any

from ..engine.backends.process import configure_process
from . import loader, manifest, own_numbers
from .pytest_plugin import ENV_IMPL
from .report import CheckReport
from .runner import ChecksDidNotRun, checks_folder, run_checks

TODO = re.compile(r"Task (\d+): (.*)", re.DOTALL)
"""The message of a template's ``raise NotImplementedError("Task N: what to do")``."""


class LiveTask:
    """One task file, imported again whenever it changed on disk since the last use.

    Attributes are the file's functions and constants: edit the file, save it
    and run the cell again to use the new code (no kernel restart).
    """

    def __init__(self, folder: Path, number: int, label: str) -> None:
        self._folder, self._number, self._label = folder, number, label
        self._stamp: tuple[int, int] | None = None
        self._module: loader.TaskModule | None = None

    def __getattr__(self, name: str) -> Any:
        return getattr(self._load(), name)

    def _load(self) -> loader.TaskModule:
        path = self._folder / f"task{self._number}.py"
        try:
            status = path.stat()
        except FileNotFoundError:
            raise loader.SubmissionError(
                f"task{self._number}.py is missing from {self._folder}"
            ) from None
        stamp = (status.st_mtime_ns, status.st_size)
        if self._module is None or stamp != self._stamp:
            implementation = loader.FolderImplementation(self._folder, self._label)
            self._module, self._stamp = implementation.task(self._number), stamp
        return self._module

    def __repr__(self) -> str:
        return f"<task {self._number} of {self._label}>"


class Course:
    """The task files a notebook studies, and its notes about unfinished tasks."""

    def __init__(self, spec: str | None = None, start: Path | None = None) -> None:
        configure_process()
        self.root = loader.course_root(Path.cwd() if start is None else start)
        self.spec = spec or os.environ.get(ENV_IMPL) or loader.DEFAULT
        self.folder = loader.resolve(self.spec, self.root)
        if not self.folder.is_dir():
            raise loader.SubmissionError(
                f"no folder of task files at {self.folder} (set by {ENV_IMPL} or Course(spec))"
            )
        self.unfinished: dict[int, str] = {}  # task -> what a cell above found missing
        self._explained: set[str] = set()  # the functions whose to-do note was printed

    @property
    def label(self) -> str:
        """The task files' folder as the user would name it ('solutions' says that they are
        the reference answers)."""
        return loader.describe(self.spec if self.spec in loader.NAMED else self._shown(self.folder))

    def task(self, number: int) -> LiveTask:
        """Task ``number``'s file of this course's implementation."""
        return LiveTask(self.folder, number, self._shown(self.folder))

    @contextmanager
    def attempt(self) -> Iterator[None]:
        """Run a cell's code; if it needs a function not written yet, say what to do instead.

        Catches the templates' ``NotImplementedError("Task N: ...")`` and task
        files that do not import, prints a short note, closes the figures the
        cell opened and lets the notebook go on. Later cells that use a result
        such a cell did not make (a ``NameError``) print a note too. Every
        other error is raised as usual.
        """
        figures = _open_figures()
        try:
            yield
        except NotImplementedError as error:
            found = TODO.match(str(error))
            if not found:
                raise
            _close_figures_since(figures)
            number, where = int(found.group(1)), self._raised_in(error.__traceback__)
            print(self._todo(number, where, found.group(2)))
            self.unfinished[number] = where
        except loader.SubmissionError as error:
            found = re.search(r"task(\d+)\.py", str(error))
            if not found:
                raise
            _close_figures_since(figures)
            number = int(found.group(1))
            self.unfinished[number] = found.group(0)
            print(f"Task {number} cannot run: {error}")
            print("  Fix it, save the file and run this cell again.")
        except NameError as error:
            if not self.unfinished:
                raise
            _close_figures_since(figures)
            waiting = ", ".join(self.unfinished[n] for n in sorted(self.unfinished))
            print(f"skipped: {error}, a result of a cell above that waits for {waiting}")

    def check(self, number: int, timeout: float = 900.0) -> CheckReport | None:
        """Run the checks of task ``number`` on these task files and print what ``msdlab check``
        prints (`CheckReport.printout`); return the report (None if they could not run)."""
        print(f"checks of task {number} on {self.label}:")
        own = own_numbers.announced(self.folder)
        print(f"  with {own}\n" if own else "")
        checks = checks_folder(None, self.root)
        with tempfile.TemporaryDirectory(prefix="msdlab-check-") as scratch:
            points = Path(scratch) / manifest.FILE_NAME
            try:
                report, _ = run_checks(checks, self.folder, number, timeout=timeout, points=points)
            except ChecksDidNotRun as error:
                print(error.output[-6000:])
                print(error)
                return None
            worth = manifest.hidden_worth(checks, points, number)
        print(report.printout(100, worth))
        return report

    def _raised_in(self, tb: TracebackType | None) -> str:
        """'name (file)' of the innermost function of the task files in the traceback."""
        where = ""
        while tb is not None:
            code = tb.tb_frame.f_code
            path = Path(code.co_filename)
            if path.parent.resolve() == self.folder:
                name = getattr(code, "co_qualname", code.co_name)  # co_qualname: Python 3.11+
                where = f"{name} ({self._shown(path)})"
            tb = tb.tb_next
        return where or self._shown(self.folder)

    def _todo(self, number: int, where: str, todo: str) -> str:
        """The note on an unwritten function: in full the first time, then one line."""
        if where in self._explained:
            return f"Task {number} is not finished: {where} is still to write (see above)."
        self._explained.add(where)
        wrap = textwrap.TextWrapper(width=92, initial_indent="  ", subsequent_indent="    ")
        return "\n".join(
            [
                f"Task {number} is not finished: {where} is still to write.",
                wrap.fill("to do: " + " ".join(todo.split())),
                f"  Write it, save the file and run this cell again; `msdlab check {number}` "
                "grades it.",
                "  Cells that need it print a note instead of running.",
            ]
        )

    def _shown(self, path: Path) -> str:
        """``path`` relative to the course folder where it is inside it."""
        try:
            return str(path.resolve().relative_to(self.root))
        except ValueError:
            return str(path)

    def __repr__(self) -> str:
        return f"<Course: task files of {self.label} in {self.root}>"


def _open_figures() -> set[int]:
    """Numbers of the open matplotlib figures (none if pyplot is not in use)."""
    pyplot = sys.modules.get("matplotlib.pyplot")
    return set(pyplot.get_fignums()) if pyplot else set()


def _close_figures_since(before: set[int]) -> None:
    """Close the figures opened since ``before``: a skipped cell shows no empty plot."""
    pyplot = sys.modules.get("matplotlib.pyplot")
    for number in _open_figures() - before:
        pyplot.close(number)
