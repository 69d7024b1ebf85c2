"""Trivial answers: a task file whose answers contain no physics, to prove no check pays them.

`answer_source` turns a solution into a trivial answer of one `KINDS` kind: every function
with a solution block still runs (so the answer has the solution's shape and type), but
what it returns is replaced by zeros, its first argument unchanged, ones, NaN, inf, an
empty array or an imaginary array. Constructors with a solution block store their
arguments unchecked. A point earned by such a file is a point for nothing.
"""

from __future__ import annotations

import ast
import functools
import types
from collections.abc import Callable
from typing import Any

import numpy as np

KINDS = ("zeros", "input", "constant", "nan", "inf", "empty", "complex")
BEGIN, END = "### BEGIN SOLUTION", "### END SOLUTION"


def answer_source(source: str, kind: str) -> str:
    """``source`` (a solution file) with every answer trivial of ``kind`` (one of `KINDS`)."""
    if kind not in KINDS:
        raise ValueError(f"no trivial answer {kind!r}: the kinds are {', '.join(KINDS)}")
    source = _unchecked_constructors(source)
    names = [".".join(path) for path in _answered(source)]
    lines = [
        "",
        "",
        "from msdlab.instructor.trivial import trivial as _msdlab_trivial",
        "",
        "_msdlab_globals = dict(globals())",
    ]
    for name in names:
        owner, _, attribute = name.rpartition(".")
        target = f"{owner}.{attribute}" if owner else attribute
        lines.append(f"{target} = _msdlab_trivial({kind!r}, {target}, _msdlab_globals)")
    return source.rstrip("\n") + "\n" + "\n".join(lines) + "\n"


def trivial(kind: str, function: Callable[..., Any], names: dict[str, Any]) -> Callable[..., Any]:
    """``function`` answering trivially; its own calls see the untouched ``names``."""
    original = function
    if isinstance(function, types.FunctionType):
        original = types.FunctionType(
            function.__code__, names, function.__name__, function.__defaults__,
            function.__closure__,
        )  # fmt: skip
        original.__kwdefaults__ = function.__kwdefaults__
    method = "." in function.__qualname__

    @functools.wraps(function)
    def answer(*args: Any, **kwargs: Any) -> Any:
        result = original(*args, **kwargs)
        given = args[1:] if method else args
        return _value(kind, result, given[0] if given else None)

    return answer


def _value(kind: str, result: Any, first: Any) -> Any:
    """The trivial stand-in for ``result``."""
    if kind == "input":
        return first
    if isinstance(result, tuple):
        return tuple(_value(kind, item, first) for item in result)
    if isinstance(result, str):
        return "" if kind in ("zeros", "empty") else kind
    array = np.asarray(result)
    fill = {"zeros": 0, "constant": 1, "nan": np.nan, "inf": np.inf, "complex": 1j}
    if kind == "empty":
        return np.empty((0, *array.shape[1:]), dtype=array.dtype)
    value = np.full(array.shape, fill[kind], dtype=complex if kind == "complex" else None)
    if kind in ("zeros", "constant") and array.dtype.kind in "iub":
        value = value.astype(array.dtype)
    return value if array.ndim else value[()]


def _answered(source: str) -> list[tuple[str, ...]]:
    """The (function,) or (class, method) paths of the definitions holding a solution block,
    constructors left out."""
    markers = _marker_lines(source)
    found = []
    for node in ast.parse(source).body:
        if isinstance(node, ast.FunctionDef) and _holds(node, markers):
            found.append((node.name,))
        elif isinstance(node, ast.ClassDef):
            found += [
                (node.name, item.name)
                for item in node.body
                if isinstance(item, ast.FunctionDef)
                and item.name != "__init__"
                and _holds(item, markers)
            ]
    return found


def _unchecked_constructors(source: str) -> str:
    """``source`` with the solution block of each ``__init__`` storing its arguments."""
    lines = source.splitlines()
    markers = _marker_lines(source)
    constructors = [
        node
        for node in ast.walk(ast.parse(source))
        if isinstance(node, ast.FunctionDef) and node.name == "__init__" and _holds(node, markers)
    ]
    for node in sorted(constructors, key=lambda n: -n.lineno):
        begin = next(n for n in markers if node.lineno <= n <= node.end_lineno)
        end = next(n for n in range(begin, len(lines) + 1) if END in lines[n - 1])
        indent = lines[begin - 1][: len(lines[begin - 1]) - len(lines[begin - 1].lstrip())]
        names = [a.arg for a in node.args.args[1:]] or ["pass"]
        body = [f"{indent}self.{n} = {n}" if n != "pass" else f"{indent}pass" for n in names]
        lines[begin - 1 : end] = body
    return "\n".join(lines) + "\n"


def _marker_lines(source: str) -> list[int]:
    return [n for n, text in enumerate(source.splitlines(), start=1) if BEGIN in text]


def _holds(node: ast.FunctionDef, markers: list[int]) -> bool:
    return any(node.lineno <= n <= (node.end_lineno or node.lineno) for n in markers)
