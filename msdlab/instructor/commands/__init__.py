"""The instructor's sub-commands of the ``msdlab`` command line, one module each, named as
the command (`msdlab.commands.command_module` imports one when it is used)."""

COMMANDS = ("templates", "grade", "similarity", "export", "gradescope", "release", "validate")
