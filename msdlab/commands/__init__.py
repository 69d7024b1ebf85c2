"""Sub-commands of the ``msdlab`` command line; each module has ``register(subparsers)``."""

from . import check, demo, grade, release, run, scenes, templates

COMMANDS = [demo, scenes, run, check, templates, grade, release]
