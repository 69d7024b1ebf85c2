"""The instructor's sub-commands of the ``msdlab`` command line."""

from . import grade, gradescope, release, similarity, templates, validate

COMMANDS = [templates, grade, similarity, gradescope, release, validate]
