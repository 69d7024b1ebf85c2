"""Sub-commands of the ``msdlab`` command line: each module, named as its command, has
``register(subparsers)``; `command_module` imports one when it is used.

The instructor's commands join them where `msdlab.instructor` is installed (not in the
student bundle, so its ``msdlab --help`` lists only what works there).
"""

from __future__ import annotations

import importlib
from types import ModuleType

STUDENT_COMMANDS = ("demo", "scenes", "run", "check", "handin")

try:
    from ..instructor.commands import COMMANDS as INSTRUCTOR_COMMANDS
except ModuleNotFoundError as missing:  # the student bundle ships without msdlab.instructor
    if missing.name != "msdlab.instructor":
        raise
    INSTRUCTOR_COMMANDS = ()

COMMANDS = (*STUDENT_COMMANDS, *INSTRUCTOR_COMMANDS)
"""The names of the commands, in the order ``msdlab --help`` lists them."""


def command_module(name: str) -> ModuleType:
    """The module of the command ``name`` (one of `COMMANDS`), imported."""
    package = "." if name in STUDENT_COMMANDS else "..instructor.commands."
    return importlib.import_module(f"{package}{name}", __name__)
