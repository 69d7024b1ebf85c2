"""A time limit on each call into a student's task module, in the checks' own process.

`time_limit` is the one real-time timer of msdlab's checks: it interrupts a block after
``seconds`` and then gives back the timer it found (pytest-timeout's, with the time that is
left of it), so a check stays under its own limit after a limited call. `limited` wraps a task
module's function (or the methods a task's class defines) so that one call may take at most
``seconds``, failing with `CallTimedOut`, whose message names the function and the check that
called it (raised again as `StopIgnored`, which ``except Exception`` does not catch, should the
code catch it and go on). A function that timed out fails at once for the rest of that check
(`forgive` starts the next check afresh), so a property check does not wait again for every
example.

Works only in the main thread of a POSIX process; elsewhere nothing is limited. Limits nest:
an inner limit longer than what is left of the outer one leaves the outer one in charge.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any, NoReturn

_LIMITED = "__msdlab_limited__"
_timed_out: set[str] = set()


class CallTimedOut(Exception):
    """A call into the task module took longer than the per-call limit."""


class StopIgnored(BaseException):
    """A stop (`CallTimedOut`, or the task budget's `TaskStopped`) that the student's code
    caught and went on after, raised again where ``except Exception`` cannot catch it; its
    ``__cause__`` is the stop."""


GRACE = 1.0
"""Seconds a block may go on after its stop before the stop is raised again as `StopIgnored`."""


@contextlib.contextmanager
def time_limit(seconds: float, expire: Callable[[], NoReturn]) -> Iterator[None]:
    """Call ``expire`` (which raises) if the block runs longer than ``seconds``; the timer and
    handler found on entry are restored on exit, the timer with the time it has left."""
    main = threading.current_thread() is threading.main_thread()
    if not main or not hasattr(signal, "setitimer"):
        yield
        return
    outer, interval = signal.getitimer(signal.ITIMER_REAL)
    if outer and outer <= seconds:  # the outer limit comes first: leave it in charge
        yield
        return

    stop: list[BaseException] = []

    def interrupt(signum: int, frame: object) -> None:
        if stop:  # the code caught the stop and went on
            raise StopIgnored(str(stop[0])) from stop[0]
        signal.setitimer(signal.ITIMER_REAL, GRACE)
        try:
            expire()
        except Exception as error:
            stop.append(error)
            raise

    previous = signal.signal(signal.SIGALRM, interrupt)
    started = time.monotonic()
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if outer:
            left = outer - (time.monotonic() - started)
            signal.setitimer(signal.ITIMER_REAL, max(left, 1e-3), interval)


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
        if name in _timed_out:
            _fail(name, file, seconds)
        with time_limit(seconds, lambda: _fail(name, file, seconds)):
            return function(*args, **kwargs)

    setattr(call, _LIMITED, True)
    return call


def _fail(name: str, file: str, seconds: float) -> NoReturn:
    """Raise `CallTimedOut` naming the function and the check, and remember the function (one
    place, so that a property check that meets it again sees the same error)."""
    _timed_out.add(name)
    check = os.environ.get("PYTEST_CURRENT_TEST", "").split("::")[-1].split(" ")[0]
    where = f" (check {check.removeprefix('test_')})" if check else ""
    raise CallTimedOut(
        f"{file}: {name} did not return within {seconds:g} s{where}: an endless loop, or "
        "far too much work? (msdlab check --call-timeout S allows more)"
    )
