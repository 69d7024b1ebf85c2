"""The instructor's sub-commands of the ``msdlab`` command line."""

from . import grade, release, templates, validate

COMMANDS = [templates, grade, release, validate]
