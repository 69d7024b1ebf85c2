"""Sub-commands of the ``msdlab`` command line; each module has ``register(subparsers)``."""

from . import check, demo, templates

COMMANDS = [demo, check, templates]
