"""The instructor's sub-commands of the ``msdlab`` command line."""

from . import export, grade, gradescope, release, templates, validate

COMMANDS = [templates, grade, export, gradescope, release, validate]
