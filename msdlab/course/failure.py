"""A failed check in the course's words: where the student's code raised, what input failed.

pytest and Hypothesis describe a failure for the people who wrote the checks (tracebacks
through the checks, "Failing test case: test_x(task2=<...>, seed=0,  # or any other
generated value)"). A student needs two things from it:

- `raised_in`: the line of their own task file where an error was raised, as Python's
  tracebacks name it (file, line, function and the line's code); where it was raised in
  the task file's given code, the student's line that called it (`outside_given_code`);
- `failing_inputs`: the inputs a property check (Hypothesis ``@given``) failed on, said
  plainly, or that it fails whatever the input.
"""

from __future__ import annotations

import linecache
import re
import traceback
from pathlib import Path

from .report import WHERE

EXAMPLE_NOTE = re.compile(r"^(Falsifying example|Failing test case): \w+\((?P<args>.*)\)\s*$", re.S)
"""Hypothesis' note on the example a property check failed on."""

ANY_VALUE = "# or any other generated value"
"""Hypothesis' comment on an argument the failure does not depend on."""

SECTION = re.compile(r"^# -{10,} (?P<name>.+?)\s*$")
"""A task file's section header, ``# ----...---- given code`` or ``... your answers``."""

ARGUMENT_CHECK = re.compile(r"\b_checked_\w+\(")
"""A call of one of the given code's checks of a function's arguments (``_checked_axis``):
what it raises is the fault of the line that called the function with those arguments."""


def raised_in(error: BaseException, folder: Path | None, code: bool = True) -> str:
    """'in your code: assignments/task2.py, line 51, in spring_acceleration' and (with
    ``code``) the line's code, for the innermost frame of ``error``'s traceback in a file of
    ``folder`` (a method named with its class); '' when the error was not raised in (or
    through) the student's files."""
    if folder is None:
        return ""
    folder = Path(folder).resolve()
    frames = [
        (frame, line)
        for frame, line in traceback.walk_tb(error.__traceback__)
        if Path(frame.f_code.co_filename).resolve().parent == folder
    ]
    if not frames:
        return ""
    frame, line = frames[outside_given_code([(f.f_code.co_filename, n) for f, n in frames])]
    path = frame.f_code.co_filename
    name = getattr(frame.f_code, "co_qualname", frame.f_code.co_name)  # Python 3.11+
    where = f"{WHERE}{folder.name}/{Path(path).name}, line {line}, in {name}"
    text = linecache.getline(path, line).strip() if code else ""
    return f"{where}\n    {text}" if text else where


def outside_given_code(frames: list[tuple[str, int]]) -> int:
    """Which of the frames (file, line) of a student's task files, outermost first, names
    where an error comes from: the innermost one outside the files' given code (the section
    under ``# ---- given code``), that is, the student's line that called the given code
    which raised; the innermost where all of them are given code. Where that line is the
    given check of its function's arguments (`ARGUMENT_CHECK`), the student's line that
    called the function with them."""
    for index in range(len(frames) - 1, -1, -1):
        if not in_given_code(*frames[index]):
            while (
                index > 0
                and ARGUMENT_CHECK.search(linecache.getline(*frames[index]))
                and not in_given_code(*frames[index - 1])
            ):
                index -= 1
            return index
    return len(frames) - 1


def in_given_code(path: str, line: int) -> bool:
    """Whether ``line`` of the task file ``path`` is in its section of given code."""
    section = ""
    for number in range(1, line + 1):
        header = SECTION.match(linecache.getline(path, number))
        if header:
            section = header["name"]
    return section == "given code"


def failing_inputs(note: str) -> str:
    """Hypothesis' note on a failing example, plainly: 'the input that failed: seed = 12'
    (the task module the check was given is left out), or 'it fails whatever the input
    (tried first: seed = 0)'; '' for any other note."""
    found = EXAMPLE_NOTE.match(note.strip())
    if not found:
        return ""
    arguments = _arguments(found["args"])
    shown = [f"{name} = {value}" for name, (value, _) in arguments.items()]
    if not shown:
        return ""
    if all(any_value for _, any_value in arguments.values()):
        return f"it fails whatever the input (tried first: {', '.join(shown)})"
    inputs = "inputs that failed" if len(shown) > 1 else "input that failed"
    return f"the {inputs}: {', '.join(shown)}"


def _arguments(text: str) -> dict[str, tuple[str, bool]]:
    """name -> (value, whether Hypothesis says any other value fails too), from the lines
    ``name=value,  # comment`` of a note (a value over several lines, such as a tuple whose
    parts carry comments of their own, joined without them); the task modules are left out."""
    found: dict[str, list[str]] = {}
    any_value: dict[str, bool] = {}
    for line in text.strip().splitlines():
        code, _, comment = line.partition("  #")
        start = re.match(r"\s*(\w+)=(.*)$", code)
        if start:
            found[start[1]] = [start[2].strip()]
            any_value[start[1]] = ANY_VALUE.lstrip("# ") in comment
        elif found and code.strip() and not code.strip().startswith("#"):
            found[list(found)[-1]].append(code.strip())
    arguments = {}
    for name, lines in found.items():
        value = " ".join(lines).strip().rstrip(",").replace("( ", "(").replace(", )", ")")
        if not value.startswith("<task module"):
            arguments[name] = (value, any_value[name])
    return arguments
