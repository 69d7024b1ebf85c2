"""No points for delegating: while a task's checks run, the engine's answer to it refuses to work
for the student's code.

Each task asks for physics the engine already has (task 5 is ``msd.Verlet`` with damping,
task 2 the engine's spring kernel, ...). `ANSWERS` names, per task, the engine entry points
that would be its answer. `install` wraps them once per process (before a submission is
imported, so ``from msdlab.engine.backends.numpy import spring_forces`` gets the wrapper
too); inside
`refusing`, a wrapped entry point of the task being checked raises `DelegationRefused` when
it is called directly from a file of the submission's folder, or (classes) when it acts on
an object of a class the submission defined, such as ``class DampedVerlet(msd.Verlet)``.
Calls from the checks, their oracles and the engine itself work as usual, and so does the
student's own code of other tasks.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import inspect
import os
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from .feedback import CheckFailed

SPRING_KERNELS = (
    "msdlab.engine.backends.numpy:spring_forces",
    "msdlab.engine.backends.numpy:spring_vectors",
)
DYNAMICS = ("msdlab.engine.dynamics:Dynamics.__init__",)
VERLET = ("msdlab.engine.integrators:Verlet.__init__", "msdlab.engine.integrators:Verlet.step")
ROTATIONS = ("msdlab.engine.model.rotation:rotation_matrix", "msdlab.engine.model.body:Body.rotate")
LATTICE = (
    "msdlab.engine.model.body:Body.grid",
    "msdlab.engine.model.lattice:neighbour_offsets",
    "msdlab.engine.model.lattice:grid_pairs",
    "msdlab.engine.model.lattice:grid_pair_blocks",
)

ANSWERS: dict[int, tuple[str, ...]] = {
    1: VERLET,  # verlet_step and height_after are a Verlet step and a Verlet run
    2: (*SPRING_KERNELS, *DYNAMICS, "msdlab.engine.model.body:Body.grid"),
    3: (*ROTATIONS, *SPRING_KERNELS, *DYNAMICS),  # its spring_acceleration is task 2's physics
    4: LATTICE,
    5: VERLET,  # a subclass of msd.Verlet delegates too: its instances are refused
}
"""Per task, the engine entry points (``module:qualified name``) that would be its answer."""

_CONDITIONS: dict[str, Callable[[inspect.BoundArguments], bool]] = {
    # a grid of particles without springs is no answer: only the engine's springs are
    "msdlab.engine.model.body:Body.grid": lambda call: bool(tuple(call.arguments["neighbours"])),
}
"""Entry points that are the answer only for some arguments: refused when this is true."""

_state: dict[str, Any] = {"task": None, "folder": None}
_installed: dict[str, Callable] = {}


class DelegationRefused(CheckFailed):
    """The student's code called the engine's answer to the task being checked."""


def describe(entry: str) -> str:
    """``msdlab.engine.integrators:Verlet.step`` -> ``msdlab.Verlet.step`` (the name students
    use)."""
    module, name = entry.split(":")
    public = name.removesuffix(".__init__")
    if public.split(".")[0] in getattr(sys.modules.get("msdlab"), "__all__", ()):
        return f"msdlab.{public}"
    return f"{module}.{public}"


def install() -> None:
    """Wrap every entry point of `ANSWERS` (once per process; inactive until `refusing`)."""
    for entry in sorted({e for entries in ANSWERS.values() for e in entries}):
        if entry in _installed:
            continue
        module_name, qualified = entry.split(":")
        module = importlib.import_module(module_name)
        owner_name, _, attribute = qualified.rpartition(".")
        owner = getattr(module, owner_name) if owner_name else module
        original = owner.__dict__[attribute]
        if isinstance(original, classmethod):
            wrapped: Any = classmethod(_guard(entry, original.__func__, method=False))
        else:
            wrapped = _guard(entry, original, method=bool(owner_name))
        setattr(owner, attribute, wrapped)
        if not owner_name and getattr(sys.modules["msdlab"], attribute, None) is original:
            setattr(sys.modules["msdlab"], attribute, wrapped)  # the public name msd.<name>
        _installed[entry] = original


@contextlib.contextmanager
def refusing(task: int | None, folder: str | Path | None) -> Iterator[None]:
    """While inside, the answers of ``task`` refuse calls from the files under ``folder``
    (None: refuse nothing)."""
    previous = dict(_state)
    set_refused(task, folder)
    try:
        yield
    finally:
        _state.update(previous)


def set_refused(task: int | None, folder: str | Path | None) -> None:
    """Refuse the answers of ``task`` to the code under ``folder`` from now on (None: nothing)."""
    if task is not None and folder is not None and task in ANSWERS:
        _state.update(task=task, folder=os.path.realpath(folder) + os.sep)
    else:
        _state.update(task=None, folder=None)


def _guard(entry: str, function: Callable, method: bool) -> Callable:
    @functools.wraps(function)
    def guarded(*args: Any, **kwargs: Any) -> Any:
        task = _state["task"]
        if task is not None and entry in ANSWERS[task]:
            caller = sys._getframe(1).f_code.co_filename
            owner = type(args[0]) if method and args else None
            if (
                _is_student(caller) or (owner is not None and _defined_by_student(owner))
            ) and _answers(entry, function, args, kwargs):
                raise DelegationRefused(
                    f"task {task} asks for your own implementation, but your code used "
                    f"{describe(entry)}, the engine's answer to it: it is refused while task "
                    f"{task} is checked. Write the physics yourself (reusing your own code of "
                    "other tasks is fine)"
                )
        return function(*args, **kwargs)

    return guarded


def _answers(entry: str, function: Callable, args: tuple, kwargs: dict) -> bool:
    """Whether this call of ``entry`` would compute the answer (see `_CONDITIONS`)."""
    condition = _CONDITIONS.get(entry)
    if condition is None:
        return True
    try:
        call = inspect.signature(function).bind(*args, **kwargs)
    except TypeError:
        return False  # the engine itself will refuse the call
    call.apply_defaults()
    return condition(call)


def _is_student(filename: str) -> bool:
    folder = _state["folder"]
    return bool(folder) and _resolved(filename).startswith(folder)


@functools.cache
def _resolved(filename: str) -> str:
    """``os.path.realpath(filename)``, once per file (a guarded step asks every step)."""
    return os.path.realpath(filename)


def _defined_by_student(cls: type) -> bool:
    """Whether ``cls`` (or a class between it and the engine's) comes from the submission."""
    for klass in cls.__mro__:
        module = sys.modules.get(klass.__module__)
        path = getattr(module, "__file__", None)
        if path and _is_student(path):
            return True
    return False
