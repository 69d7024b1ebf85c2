"""The imports of msdlab flow one way: no cycles, no upward imports, no hidden imports in the
engine. The layers are msdlab's folders; a module may import its own layer and those below.

msdlab's layers, lowest first, are ``FOLDERS``: ``engine``; ``analysis`` and ``interaction``,
built on it; the package ``msdlab`` itself (its ``__init__`` names the public names of the
layers below); ``scenes`` and ``course``; ``viz``; ``instructor``; ``commands``; and last the
modules directly in ``msdlab/``, the ways in (``cli``,
``__main__``, the Jupyter server's ``jupyter_extension``).

The engine's layers, lowest first, are what ``msdlab/engine/`` holds, a folder or a module
each (``ENGINE``, as its ``__init__`` describes them): ``equations``, ``model``,
``backends``, ``dynamics``, ``integrators``, ``simulation``. Every folder and module is
in one layer: the test fails for one it does not know.

Imports under ``if TYPE_CHECKING:`` are for type hints only and are not counted.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "msdlab"
FOLDERS = [
    ("engine",),
    ("analysis", "interaction"),
    ("",),  # the package msdlab: its __init__
    ("scenes", "course"),
    ("viz",),
    ("instructor",),
    ("commands",),
]
ENGINE = ["equations", "model", "backends", "dynamics", "integrators", "simulation"]
# The one import made inside a function in the engine: a compiled backend, when chosen.
LOADS_BACKENDS = "msdlab.engine.backends.choice"
COMPILED = ("msdlab.engine.backends.numba", "msdlab.engine.backends.warp")


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def layer(module: str) -> tuple[int, int]:
    """The layer of a module: its folder's place in `FOLDERS` (the modules directly in
    msdlab/ last), and within the engine its folder's or module's place in `ENGINE`."""
    parts = module.split(".")[1:]
    if not parts:
        return FOLDERS.index(("",)), 0
    if MODULES[module].parent == PACKAGE and MODULES[module].name != "__init__.py":
        return len(FOLDERS), 0
    outer = next(i for i, names in enumerate(FOLDERS) if parts[0] in names)
    return outer, ENGINE.index(parts[1]) if parts[0] == "engine" and len(parts) > 1 else -1


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


def test_every_folder_and_engine_layer_is_known() -> None:
    """A folder or engine module added is placed in a layer before it can be imported."""
    folders = {path.name for path in PACKAGE.iterdir() if (path / "__init__.py").exists()}
    assert folders == {name for names in FOLDERS for name in names if name}
    inside = {path.stem for path in (PACKAGE / "engine").iterdir() if path.suffix == ".py"}
    inside |= {path.name for path in (PACKAGE / "engine").iterdir() if path.is_dir()}
    assert inside - {"__init__", "__pycache__"} == set(ENGINE)


def test_the_parser_sees_the_imports() -> None:
    """A check that finds nothing proves nothing: known imports are found."""
    assert ("msdlab.engine.equations", False) in GRAPH["msdlab.engine.backends.numpy"]
    assert ("msdlab.engine.backends.numba", True) in GRAPH[LOADS_BACKENDS]
    assert ("msdlab.engine.model.body", False) in GRAPH["msdlab.interaction.constraints"]
    assert layer("msdlab.engine.model.body") < layer("msdlab.engine.dynamics")
    assert layer("msdlab.engine.dynamics") < layer("msdlab.analysis.measure") < layer("msdlab")
    assert layer("msdlab.commands") < layer("msdlab.cli")


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
        if target in MODULES and layer(target) > layer(module)
    ]
    assert not upward, "\n".join(upward)


def test_the_engine_imports_at_the_top_of_its_modules() -> None:
    hidden = [
        f"{module} imports {target} inside a function"
        for module, targets in GRAPH.items()
        for target, in_function in targets
        if module.startswith("msdlab.engine.")
        and in_function
        and not (module == LOADS_BACKENDS and target.startswith(COMPILED))
    ]
    assert not hidden, "\n".join(hidden)


def test_only_the_kernel_choice_loads_a_compiled_backend() -> None:
    """Importing msdlab needs no numba: a compiled backend is loaded by `make_kernel` alone."""
    loaders = {
        (module, in_function)
        for module, targets in GRAPH.items()
        for target, in_function in targets
        if target.startswith(COMPILED) and not module.startswith(COMPILED)
    }
    assert loaders == {(LOADS_BACKENDS, True)}
