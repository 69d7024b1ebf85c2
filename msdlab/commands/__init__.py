"""Sub-commands of the ``msdlab`` command line; each module has ``register(subparsers)``."""

from . import check, demo, grade, run, scenes, templates

COMMANDS = [demo, scenes, run, check, templates, grade]
