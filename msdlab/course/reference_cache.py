"""Reference numbers computed once per grading run instead of once per submission.

The checks compare a submission with references that do not depend on it (the
engine's run of the same experiment, a predicted stable dt). `cached` keeps such
a number or array in the folder named by ``$MSDLAB_REFERENCE_CACHE``, which
`msdlab.instructor.judging.grading.grade_all` creates for one run (readable only by the
grader, not by the sandboxed submissions); the next submission's judge reads it
back bit for bit. Without the variable (``msdlab check``, ``pytest --impl``,
``msdlab validate``) the function simply runs.
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
from typing import TypeVar

import numpy as np

ENV = "MSDLAB_REFERENCE_CACHE"
Value = TypeVar("Value", float, np.ndarray)


def cached(function: Callable[..., Value]) -> Callable[..., Value]:
    """``function`` (returning one number or a numpy array) with its results kept in
    ``$MSDLAB_REFERENCE_CACHE``, keyed by its source and its arguments."""
    source = inspect.getsource(function)

    @functools.wraps(function)
    def wrapper(*args: object, **kwargs: object) -> Value:
        folder = os.environ.get(ENV)
        if not folder:
            return function(*args, **kwargs)
        call = repr((function.__qualname__, source, args, sorted(kwargs.items())))
        stem = Path(folder) / hashlib.sha256(call.encode()).hexdigest()
        number, array = stem.with_suffix(".json"), stem.with_suffix(".npy")
        try:
            if array.is_file():
                return np.load(array, allow_pickle=False)
            return float(json.loads(number.read_text(encoding="utf-8"))["value"])
        except (OSError, ValueError, KeyError, TypeError):
            pass
        value = function(*args, **kwargs)
        handle, temporary = tempfile.mkstemp(dir=folder, suffix=".part")
        with os.fdopen(handle, "wb") as out:
            if isinstance(value, np.ndarray):
                np.save(out, value, allow_pickle=False)  # every bit, dtype and shape
            else:
                value = float(value)
                out.write(json.dumps({"value": value}).encode())  # floats round-trip exactly
        os.replace(temporary, array if isinstance(value, np.ndarray) else number)
        return value

    return wrapper
