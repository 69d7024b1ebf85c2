"""The ``public-names`` directive: a package's ``__all__`` as an autosummary table.

Each name links to where it is documented, the module that defines it (``msdlab.Body``
is `msdlab.engine.model.body.Body`), and shows the first sentence of its docstring::

    .. public-names:: msdlab
"""

from __future__ import annotations

import importlib

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util.docutils import SphinxDirective


def defined_names(package: str) -> list[str]:
    """``module.name`` of each name of the package's ``__all__``, where it is defined,
    relative to the package (the page's current module: autosummary wants them so)."""
    module = importlib.import_module(package)
    defined = [f"{getattr(module, name).__module__}.{name}" for name in module.__all__]
    return [name.removeprefix(f"{package}.") for name in defined]


class PublicNames(SphinxDirective):
    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        lines = [".. autosummary::", ""]
        lines += [f"   ~{name}" for name in defined_names(self.arguments[0])]
        container = nodes.container()
        source = self.get_source_info()[0]
        self.state.nested_parse(StringList(lines, source=source), self.content_offset, container)
        return container.children


def setup(app) -> dict[str, bool]:
    app.add_directive("public-names", PublicNames)
    return {"parallel_read_safe": True}
