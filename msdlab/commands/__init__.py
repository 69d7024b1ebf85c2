"""Sub-commands of the ``msdlab`` command line; each module has ``register(subparsers)``.

The instructor's commands join them where `msdlab.instructor` is installed (not in the
student bundle, so its ``msdlab --help`` lists only what works there).
"""

from . import check, demo, run, scenes

try:
    from ..instructor.commands import COMMANDS as INSTRUCTOR_COMMANDS
except ModuleNotFoundError as missing:  # the student bundle ships without msdlab.instructor
    if missing.name != "msdlab.instructor":
        raise
    INSTRUCTOR_COMMANDS = []

COMMANDS = [demo, scenes, run, check, *INSTRUCTOR_COMMANDS]
