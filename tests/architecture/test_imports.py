"""The imports of msdlab flow one way: no cycles, no upward imports, no hidden imports in the core.

The layers, lowest first; a module may import its own layer and the layers below:

0. the engine core: the modules directly in ``msdlab/`` (body, equations, the kernel
   interface ``spring_kernel``, the numpy kernel ``kernels``, the Jacobian pattern
   ``jacobian``, dynamics, stability, ...) and its numba backend ``msdlab.compiled``,
   which only ``spring_kernel`` loads, when asked to
1. ``msdlab.analysis`` and ``msdlab.interaction``, built on the core
2. the package ``msdlab`` itself (its ``__init__`` re-exports 0 and 1)
3. ``msdlab.scenes`` and ``msdlab.course``
4. ``msdlab.viz`` and ``msdlab.jupyter_extension`` (the Jupyter server's side of the live
   view and of the course's notebooks)
5. ``msdlab.instructor``
6. ``msdlab.commands``
7. ``msdlab.cli``, the process settings it makes (``msdlab.process``) and ``msdlab.__main__``

Imports under ``if TYPE_CHECKING:`` are for type hints only and are not counted.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "msdlab"
LAYERS = {
    "compiled": 0,
    "analysis": 1,
    "interaction": 1,
    "scenes": 3,
    "course": 3,
    "viz": 4,
    "jupyter_extension": 4,
    "instructor": 5,
    "commands": 6,
    "cli": 7,
    "process": 7,
    "__main__": 7,
}
# The one import made inside a function in the core: the optional compiled backend.
ALLOWED_LOCAL_IMPORTS = {("msdlab.spring_kernel", "msdlab.compiled")}


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def layer(module: str) -> int:
    """The layer of a module (see the module docstring)."""
    parts = module.split(".")
    if len(parts) == 1:
        return 2
    return LAYERS.get(parts[1], 0)


def is_type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
    )


def resolve(module: str, node: ast.ImportFrom | ast.Import) -> list[str]:
    """The msdlab modules an import statement of ``module`` loads."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names if alias.name.split(".")[0] == "msdlab"]
    if node.level:
        package = module.split(".")
        if MODULES[module].name != "__init__.py":
            package = package[:-1]
        base = package[: len(package) - node.level + 1]
        target = ".".join(base + ([node.module] if node.module else []))
    else:
        target = node.module or ""
    if target.split(".")[0] != "msdlab":
        return []
    names = [f"{target}.{alias.name}" for alias in node.names]
    submodules = [name for name in names if name in MODULES]
    return submodules or [target]


def imports(module: str) -> list[tuple[str, bool]]:
    """(imported msdlab module, made inside a function) for every runtime import of ``module``."""
    tree = ast.parse(MODULES[module].read_text(encoding="utf-8"))
    found: list[tuple[str, bool]] = []

    def visit(node: ast.AST, in_function: bool) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and is_type_checking(child):
                continue
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                found.extend((target, in_function) for target in resolve(module, child))
            inner = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
            visit(child, inner)

    visit(tree, False)
    return found


GRAPH = {module: imports(module) for module in MODULES}


def test_the_parser_sees_the_imports() -> None:
    """A check that finds nothing proves nothing: known imports are found."""
    assert ("msdlab.equations", False) in GRAPH["msdlab.kernels"]
    assert ("msdlab.compiled", True) in GRAPH["msdlab.spring_kernel"]
    assert ("msdlab.body", False) in GRAPH["msdlab.interaction.constraints"]
    assert layer("msdlab.dynamics") == 0 < layer("msdlab.analysis.measure") < layer("msdlab")


def test_no_import_cycles() -> None:
    done: set[str] = set()

    def walk(module: str, path: list[str]) -> None:
        if module in path:
            cycle = path[path.index(module) :] + [module]
            pytest.fail("import cycle: " + " -> ".join(cycle))
        if module in done:
            return
        for target, _ in GRAPH.get(module, []):
            if target != module and not module.startswith(target + "."):
                walk(target, [*path, module])
        done.add(module)

    for module in GRAPH:
        walk(module, [])


def test_imports_only_go_down_the_layers() -> None:
    upward = [
        f"{module} (layer {layer(module)}) imports {target} (layer {layer(target)})"
        for module, targets in GRAPH.items()
        for target, _ in targets
        if layer(target) > layer(module)
    ]
    assert not upward, "\n".join(upward)


def test_the_core_imports_at_the_top_of_its_modules() -> None:
    hidden = [
        f"{module} imports {target} inside a function"
        for module, targets in GRAPH.items()
        for target, in_function in targets
        if layer(module) == 0 and in_function and (module, target) not in ALLOWED_LOCAL_IMPORTS
    ]
    assert not hidden, "\n".join(hidden)


def test_only_the_kernel_choice_loads_the_numba_backend() -> None:
    """Importing msdlab needs no numba: the backend is loaded by `make_kernel` alone."""
    loaders = {
        (module, in_function)
        for module, targets in GRAPH.items()
        for target, in_function in targets
        if target.startswith("msdlab.compiled") and not module.startswith("msdlab.compiled")
    }
    assert loaders == {("msdlab.spring_kernel", True)}
