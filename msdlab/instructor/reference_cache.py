"""Reference numbers computed once per grading run instead of once per submission.

The hidden checks compare a submission with references that do not depend on it
(a whole simulation each, about a second). `cached` keeps such a number in the
folder named by ``$MSDLAB_REFERENCE_CACHE``, which `grading.grade_all` creates for
one run (readable only by the grader, not by the sandboxed submissions); the
next submission's judge reads it back bit for bit. Without the variable the
function simply runs.
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

ENV = "MSDLAB_REFERENCE_CACHE"


def cached(function: Callable[..., float]) -> Callable[..., float]:
    """``function`` (returning one number) with its results kept in ``$MSDLAB_REFERENCE_CACHE``,
    keyed by its source and its arguments."""
    source = inspect.getsource(function)

    @functools.wraps(function)
    def wrapper(*args: object, **kwargs: object) -> float:
        folder = os.environ.get(ENV)
        if not folder:
            return function(*args, **kwargs)
        call = repr((function.__qualname__, source, args, sorted(kwargs.items())))
        path = Path(folder) / (hashlib.sha256(call.encode()).hexdigest() + ".json")
        try:
            return float(json.loads(path.read_text(encoding="utf-8"))["value"])
        except (OSError, ValueError, KeyError, TypeError):
            pass
        value = float(function(*args, **kwargs))
        handle, temporary = tempfile.mkstemp(dir=folder, suffix=".part")
        with os.fdopen(handle, "w", encoding="utf-8") as out:
            json.dump({"value": value}, out)  # floats round-trip exactly through JSON
        os.replace(temporary, path)
        return value

    return wrapper
