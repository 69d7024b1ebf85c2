"""Loading a submission: the task modules of a folder laid out like ``assignments/``.

The checks never import a student package; they get an `Implementation` from
the pytest plugin and ask it for ``implementation.task(n)``, a module-like
object whose attributes are the task's functions and classes. `load` makes the
implementation from an ``--impl`` value; a grader that runs submissions
elsewhere (in a sandbox, another process) provides another object with the
same ``label`` and ``task(n)`` by overriding the plugin's ``implementation``
fixture in a ``conftest.py``.
"""

from __future__ import annotations

import hashlib
import importlib.util
import sys
import traceback
from pathlib import Path
from types import ModuleType
from typing import Any, Protocol

from . import call_limit

NAMED = ("solutions", "assignments")
ENV_IMPL = "MSDLAB_IMPL"
"""The environment variable that names the task files to check when ``--impl`` does not."""


class SubmissionError(Exception):
    """A task file that is missing or cannot be imported."""


class Implementation(Protocol):
    """What the checks use: a label for reports and the module-like object of each task."""

    label: str

    def task(self, number: int) -> Any:
        """The task's module-like object: attributes are its functions and classes."""


class TaskModule:
    """A loaded task file; a missing name gives an error that says which file lacks it."""

    def __init__(self, module: ModuleType, path: Path, call_timeout: float = 0.0) -> None:
        self._module = module
        self._path = path
        self._call_timeout = call_timeout  # seconds per call (0: no limit), see `call_limit`

    def __getattr__(self, name: str) -> Any:
        try:
            value = getattr(self._module, name)
        except AttributeError:
            if not name.startswith("__") and self._is_empty():
                raise AttributeError(
                    f"{self._path.name} is empty: start again from the template's "
                    f"{self._path.name} and write the task in it (file {self._path})"
                ) from None
            raise AttributeError(
                f"{self._path.name} has no '{name}': keep the names of the template "
                f"(file {self._path})"
            ) from None
        return call_limit.limited(value, self._call_timeout, self._path.name)

    def _is_empty(self) -> bool:
        """Whether the task file holds nothing but blank lines (saved empty, or emptied)."""
        try:
            return not self._path.read_text(encoding="utf-8", errors="replace").strip()
        except OSError:
            return False

    def __repr__(self) -> str:
        return f"<task module {self._path}>"


class FolderImplementation:
    """Task files ``task1.py`` ... ``task5.py`` of one folder, each imported by file path.

    Each folder gets its own module names, so several implementations (the
    solutions and a student's folder) can be loaded in one process.
    """

    def __init__(self, folder: Path, label: str | None = None, call_timeout: float = 0.0) -> None:
        self.folder = Path(folder).resolve()
        self.call_timeout = call_timeout
        if not self.folder.is_dir():
            raise SubmissionError(f"no implementation folder at {self.folder}")
        self.label = label or str(self.folder)
        self._prefix = "msdlab_impl_" + hashlib.sha1(str(self.folder).encode()).hexdigest()[:10]
        self._modules: dict[int, TaskModule] = {}

    def task(self, number: int) -> TaskModule:
        if number not in self._modules:
            path = self.folder / f"task{number}.py"
            module = self._import(number, path)
            self._modules[number] = TaskModule(module, path, self.call_timeout)
        return self._modules[number]

    def _import(self, number: int, path: Path) -> ModuleType:
        if not path.is_file():
            raise SubmissionError(f"task{number}.py is missing from {self.folder}")
        name = f"{self._prefix}_task{number}"
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None or spec.loader is None:
            raise SubmissionError(f"{path} cannot be loaded as a Python module")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except Exception as error:
            del sys.modules[name]
            where = _line_in(error, path)
            raise SubmissionError(
                f"task{number}.py could not be imported{where}: {type(error).__name__}: {error}"
            ) from error
        return module

    def __repr__(self) -> str:
        return f"FolderImplementation({str(self.folder)!r})"


def resolve(spec: str | Path, root: Path) -> Path:
    """The folder named by an ``--impl`` value: 'solutions', 'assignments' or a path.

    Names are folders of the course ``root``; a path is taken as it is
    (relative to the working directory).
    """
    text = str(spec)
    if text in NAMED:
        return (root / text).resolve()
    return Path(text).expanduser().resolve()


DEFAULT = "assignments"
"""The task files checked when nothing asks for others: the student's, even in a checkout that
holds ``solutions/`` (the reference answers are checked only when asked: ``--impl solutions``,
``$MSDLAB_IMPL``)."""


def describe(spec: str | Path) -> str:
    """How outputs name an ``--impl`` value: the reference answers say that they are."""
    if str(spec) == "solutions":
        return "solutions (the reference answers, not your task files)"
    return str(spec)


def course_root(start: Path) -> Path:
    """The nearest folder at or above ``start`` holding ``solutions/`` or ``assignments/``."""
    start = start.resolve()
    for folder in (start, *start.parents):
        if any((folder / name).is_dir() for name in NAMED):
            return folder
    return start


def load(spec: str | Path, root: Path, call_timeout: float = 0.0) -> FolderImplementation:
    """The implementation an ``--impl`` value names (see `resolve`); each call into it may
    take ``call_timeout`` seconds (0: no limit)."""
    folder = resolve(spec, root)
    label = str(spec) if str(spec) in NAMED else str(folder)
    return FolderImplementation(folder, label, call_timeout)


def _line_in(error: BaseException, path: Path) -> str:
    if isinstance(error, SyntaxError) and error.lineno:
        return f" (line {error.lineno})"
    lines = [f.lineno for f in traceback.extract_tb(error.__traceback__) if f.filename == str(path)]
    return f" (line {lines[-1]})" if lines else ""
