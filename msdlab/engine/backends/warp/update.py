"""An integrator's update compiled for Warp, and the particle pass that runs it.

An update is a plain function of numbers, ``update(x, v, a, dt, *coefficients) ->
(x_new, v_new)`` (`integrators.Verlet.update`, or a student's), which numba compiles as
written. Warp compiles its own typed subset of Python, in which a bare ``2.0`` is a float32
and every argument needs a type: `warp_function` reads the update's source and gives Warp
the same function with its arguments typed as the backend's scalar (float64 by default)
and each number written in it made that scalar, which is what Python's numbers are. The
result is the student's arithmetic, operation for operation, in double precision.

Warp reads a function's source to compile it; the typed copy's source is registered with
Python's `linecache` under a name of its own, as an interactive session's cells are. An
update Warp cannot compile (one calling numpy, taking ``*args``, reading variables of an
enclosing function, with more than `MOST_COEFFICIENTS` coefficients) raises `NotCompiled`
saying why, and the backend runs it on the host, on whole arrays, saying so once.
"""

import ast
import hashlib
import inspect
import linecache
import textwrap
from collections.abc import Callable
from typing import Any

import warp as wp

from .kernels import DAMPING, GROUND, NOT_FINITE, Kernels

MOST_COEFFICIENTS = 4  # the particle pass passes this many; an update takes up to these
SCALAR = "_msdlab_scalar"  # the name the typed copy calls the scalar type by


class NotCompiled(Exception):
    """Warp cannot compile an update; the message says why, in a user's words."""


class TypedNumbers(ast.NodeTransformer):
    """Makes each number written in a function the scalar type: ``2.0`` -> ``scalar(2.0)``."""

    def visit_Constant(self, node: ast.Constant) -> ast.AST:
        value = node.value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return node
        call = ast.Call(ast.Name(SCALAR, ast.Load()), [ast.Constant(float(value))], [])
        return ast.copy_location(call, node)


def typed_source(update: Callable) -> tuple[str, str, int]:
    """The source of ``update`` with its arguments typed and its numbers made the scalar type,
    padded with unused coefficients to `MOST_COEFFICIENTS`; its name and its coefficients."""
    where = f"{update.__qualname__}"
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(update)))
    except (OSError, TypeError, SyntaxError):
        raise NotCompiled(f"the source of {where} cannot be read") from None
    function = tree.body[0]
    if not isinstance(function, ast.FunctionDef):
        raise NotCompiled(f"{where} is not written with def (a lambda?)")
    arguments = function.args
    if arguments.vararg or arguments.kwarg or arguments.kwonlyargs or arguments.defaults:
        raise NotCompiled(f"{where} takes *args, **kwargs, keyword-only or default arguments")
    if update.__code__.co_freevars:
        raise NotCompiled(f"{where} reads variables of the function it is defined in")
    names = [argument.arg for argument in (*arguments.posonlyargs, *arguments.args)]
    coefficients = len(names) - 4
    if not 0 <= coefficients <= MOST_COEFFICIENTS:
        raise NotCompiled(
            f"{where} takes {len(names)} arguments; an update takes x, v, a, dt and at most "
            f"{MOST_COEFFICIENTS} coefficients"
        )
    padding = [f"_unused_{n}" for n in range(MOST_COEFFICIENTS - coefficients)]
    arguments.posonlyargs = []
    arguments.args = [ast.arg(name, ast.Name(SCALAR, ast.Load())) for name in (*names, *padding)]
    arguments.defaults = []
    function.decorator_list, function.returns = [], None
    tree = ast.fix_missing_locations(TypedNumbers().visit(tree))
    return ast.unparse(tree), function.name, coefficients


def warp_function(update: Callable, scalar: type) -> tuple[Any, str]:
    """``update`` as a Warp function of ``scalar`` and the Warp module it is in (named after
    its typed source, so the same update is compiled once and kept in Warp's cache)."""
    source, name, _ = typed_source(update)
    digest = hashlib.sha256(f"{scalar.__name__}\n{source}".encode()).hexdigest()[:16]
    module = f"msdlab_update_{digest}"
    filename = f"<msdlab update {update.__qualname__} {digest}>"
    linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
    namespace = {**update.__globals__, SCALAR: scalar, "__name__": module}
    exec(compile(source, filename, "exec"), namespace)  # the typed copy, readable by Warp
    return wp.func(namespace[name], module=module), module


def particle_pass(update: Callable, kernels: Kernels, device: Any) -> Any:
    """The kernel of a step's particle pass around ``update``, one thread per particle:
    a = (F + m·g)/m, the update, then, as asked, the fixed particles put back where they
    were at rest, the ground's clamp (`kernels.clamp_particle`) and the integrator's
    damping work; and the count of coordinates that are not finite. Compiled for ``device``
    now (or loaded from Warp's cache); raises `NotCompiled` with Warp's reason if it cannot."""
    function, module = warp_function(update, kernels.scalar)
    scalar, functions = kernels.scalar, kernels.functions
    wp.set_module_options({"enable_backward": False, "fuse_fp": False}, wp.get_module(module))
    acceleration_of, clamp, damping_kick_work = (
        functions["particle_acceleration"], functions["clamp"], functions["damping_kick_work"]
    )  # fmt: skip
    array, table = wp.array2d(dtype=scalar), wp.array(dtype=scalar)

    @wp.kernel(module=module)
    def particle_step(
        x: array, v: array, forces: array, others: array, masses: table, free: table,
        field: wp.types.vector(3, scalar), dt: scalar, c: table, pin: int,
        plane: wp.types.vector(4, scalar), keep: scalar, ground: int, factor: scalar,
        x_new: array, v_new: array, bins: array,
    ):  # fmt: skip
        i = wp.tid()
        for q in range(x.shape[1]):
            a = acceleration_of(i, q, forces, others, masses, free, field)
            moved, speed = function(x[i, q], v[i, q], a, dt, c[0], c[1], c[2], c[3])
            if pin != 0 and free[i] == scalar(0.0):
                moved = x[i, q]
                speed = scalar(0.0)
            x_new[i, q] = moved
            v_new[i, q] = speed
        if ground != 0 and free[i] != scalar(0.0):
            wp.atomic_add(
                bins,
                i % bins.shape[0],
                GROUND,
                clamp(i, x_new, v_new, x, v, masses[i], plane, dt, keep),
            )
        work = scalar(0.0)
        for q in range(x.shape[1]):
            if factor != scalar(1.0):
                work += damping_kick_work(masses[i], factor, v[i, q], v_new[i, q])
            if not (wp.isfinite(x_new[i, q]) and wp.isfinite(v_new[i, q])):
                wp.atomic_add(bins, i % bins.shape[0], NOT_FINITE, scalar(1.0))
        if work != scalar(0.0):
            wp.atomic_add(bins, i % bins.shape[0], DAMPING, -work)

    compile_now(module, device)
    return particle_step


def compile_now(module: str, device: Any) -> None:
    """Compile the Warp ``module`` for ``device`` now (or load it from Warp's cache), or raise
    `NotCompiled` with the first line of Warp's reason."""
    try:
        wp.load_module(module, device=device)
    except Exception as error:  # Warp's compile errors have no common type
        reason = str(error).strip().splitlines()
        raise NotCompiled(f"Warp says: {reason[0] if reason else type(error).__name__}") from None
