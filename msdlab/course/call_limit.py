"""A time limit on each call into a student's task module, in the checks' own process.

`limited` wraps a task module's function (or the methods a task's class defines)
so that one call may take at most ``seconds``: a real-time timer
(`signal.setitimer`) interrupts it with `CallTimedOut`, whose message names the
function and the check that called it. A function that timed out fails at once
for the rest of that check (`forgive` starts the next check afresh), so a
property check does not wait again for every example it tries.

Works only in the main thread of a POSIX process; elsewhere calls are not limited.
Calls made while another limited call is running count toward the outer one.
"""

from __future__ import annotations

import functools
import inspect
import os
import signal
import threading
from collections.abc import Callable
from typing import Any

_LIMITED = "__msdlab_limited__"
_timed_out: set[str] = set()
_running = False


class CallTimedOut(Exception):
    """A call into the task module took longer than the per-call limit."""


def forgive() -> None:
    """Let functions that timed out in the previous check run again."""
    _timed_out.clear()


def limited(value: Any, seconds: float, file: str) -> Any:
    """``value`` with every call limited to ``seconds`` (functions, and the methods a class
    defines itself); other values unchanged. ``file`` names the task file in messages."""
    if seconds <= 0 or not hasattr(signal, "setitimer") or getattr(value, _LIMITED, False):
        return value
    if inspect.isclass(value):
        for name, member in list(vars(value).items()):
            if inspect.isfunction(member) and (not name.startswith("__") or name == "__init__"):
                setattr(value, name, _wrap(member, seconds, f"{value.__name__}.{name}", file))
        setattr(value, _LIMITED, True)
        return value
    if inspect.isfunction(value):
        return _wrap(value, seconds, value.__name__, file)
    return value


def _wrap(function: Callable, seconds: float, name: str, file: str) -> Callable:
    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        global _running
        if _running or threading.current_thread() is not threading.main_thread():
            return function(*args, **kwargs)
        if name in _timed_out:
            _fail(name, file, seconds)

        def expire(signum: int, frame: object) -> None:
            _fail(name, file, seconds)

        previous = signal.signal(signal.SIGALRM, expire)
        _running = True
        try:
            signal.setitimer(signal.ITIMER_REAL, seconds)
            return function(*args, **kwargs)
        except CallTimedOut:
            _timed_out.add(name)
            raise
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)
            _running = False

    setattr(call, _LIMITED, True)
    return call


def _fail(name: str, file: str, seconds: float) -> None:
    """Raise `CallTimedOut` naming the function and the check (one place, so that a property
    check that meets it again sees the same error)."""
    check = os.environ.get("PYTEST_CURRENT_TEST", "").split("::")[-1].split(" ")[0]
    where = f" (check {check.removeprefix('test_')})" if check else ""
    raise CallTimedOut(
        f"{file}: {name} did not return within {seconds:g} s{where}: an endless loop, or "
        "far too much work? (msdlab check --call-timeout S allows more)"
    )
