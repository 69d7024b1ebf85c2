"""The instructor's sub-commands of the ``msdlab`` command line."""

from . import export, grade, gradescope, release, similarity, templates, validate

COMMANDS = [templates, grade, similarity, export, gradescope, release, validate]
