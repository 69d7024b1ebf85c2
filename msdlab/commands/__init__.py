"""Sub-commands of the ``msdlab`` command line; each module has ``register(subparsers)``."""

from . import demo, run, scenes

COMMANDS = [demo, scenes, run]
