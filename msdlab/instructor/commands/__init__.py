"""The instructor's sub-commands of the ``msdlab`` command line."""

from . import grade, gradescope, release, templates, validate

COMMANDS = [templates, grade, gradescope, release, validate]
