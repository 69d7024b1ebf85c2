"""Student templates generated from the reference solutions.

A solution file marks each piece of code the student writes::

    def particle_count(n: int = N) -> int:
        \"\"\"How many particles ...\"\"\"
        ### BEGIN SOLUTION
        # TODO: count the particles of an n × n × n grid.
        return n**3
        ### END SOLUTION

The template keeps everything outside the blocks (signature, type hints,
docstring, given code) and replaces each block by
``raise NotImplementedError("Task 1: count the particles of an n × n × n grid.")``.
The ``# TODO:`` comment (it may go on over further ``#`` lines) is required: it
is what the student reads when a check calls the unfinished function. The numbers a
student reads are markers ``{{ name }}`` filled in from the course's or the student's
own numbers (`own_numbers.filled`).
"""

from __future__ import annotations

import ast
import re
import textwrap
from dataclasses import dataclass
from pathlib import Path

from ..course import own_numbers

BEGIN = "### BEGIN SOLUTION"
END = "### END SOLUTION"
TODO = "# TODO:"
LINE_LENGTH = 100  # the project's formatter line length
TASK_FILE = re.compile(r"task(\d+)\.py")


class TemplateError(ValueError):
    """A solution file whose solution blocks cannot be turned into a template."""


@dataclass(frozen=True)
class Difference:
    """A template that is not what the generator makes from its solution."""

    path: Path
    reason: str

    def __str__(self) -> str:
        return f"{self.path}: {self.reason}"


def make_template(source: str, task: int, name: str = "<solution>") -> str:
    """The template of one solution file: every solution block becomes a ``raise``."""
    lines = source.splitlines()
    out: list[str] = []
    index = 0
    blocks = 0
    while index < len(lines):
        line = lines[index]
        stripped = line.strip()
        if stripped == END:
            raise TemplateError(f"{name}:{index + 1}: {END} without {BEGIN}")
        if stripped != BEGIN:
            out.append(line)
            index += 1
            continue
        indent = line[: len(line) - len(line.lstrip())]
        end = _block_end(lines, index, indent, name)
        todo = _todo_text(lines[index + 1 : end], indent, f"{name}:{index + 2}")
        out.extend(_raise_lines(indent, f"Task {task}: {todo}"))
        blocks += 1
        index = end + 1
    if blocks == 0:
        raise TemplateError(f"{name}: no {BEGIN} / {END} block: nothing for the student to write")
    template = "\n".join(out) + "\n"
    _check_same_interface(source, template, name)
    return template


def solution_files(solutions: Path) -> list[Path]:
    """The task files ``taskN.py`` of a solutions folder, in task order."""
    if not solutions.is_dir():
        raise FileNotFoundError(f"no solutions folder at {solutions}")
    files = [p for p in solutions.iterdir() if TASK_FILE.fullmatch(p.name)]
    if not files:
        raise FileNotFoundError(f"{solutions} holds no task files (task1.py, task2.py, ...)")
    return sorted(files, key=task_number)


def render(solutions: Path, own: own_numbers.Numbers = own_numbers.DEFAULT) -> dict[str, str]:
    """The template text of every task file of ``solutions``, by file name, with the
    numbers ``own`` (the course's defaults unless a student's own, `own_numbers`)."""
    return {
        path.name: own_numbers.personalised(
            task_number(path),
            make_template(path.read_text(encoding="utf-8"), task_number(path), str(path)),
            own,
        )
        for path in solution_files(solutions)
    }


def task_number(path: Path) -> int:
    """N of a task file ``taskN.py``."""
    match = TASK_FILE.fullmatch(path.name)
    if match is None:
        raise ValueError(f"{path.name} is not a task file (task1.py, task2.py, ...)")
    return int(match.group(1))


def generate(solutions: Path, assignments: Path) -> list[Path]:
    """Write the templates of ``solutions`` into ``assignments``; return the files written."""
    assignments.mkdir(parents=True, exist_ok=True)
    written = []
    for file_name, text in render(solutions).items():
        path = assignments / file_name
        path.write_text(text, encoding="utf-8")
        written.append(path)
    return written


def differences(solutions: Path, assignments: Path) -> list[Difference]:
    """Templates in ``assignments`` that are missing, stale or not made from a solution."""
    expected = render(solutions)
    found = []
    for file_name, text in expected.items():
        path = assignments / file_name
        if not path.exists():
            found.append(Difference(path, "missing"))
        elif path.read_text(encoding="utf-8") != text:
            found.append(Difference(path, f"differs from the template of {solutions / file_name}"))
    if assignments.is_dir():
        for path in sorted(assignments.iterdir()):
            if TASK_FILE.fullmatch(path.name) and path.name not in expected:
                found.append(Difference(path, "has no solution file"))
    return found


def _block_end(lines: list[str], begin: int, indent: str, name: str) -> int:
    for index in range(begin + 1, len(lines)):
        stripped = lines[index].strip()
        if stripped == BEGIN:
            raise TemplateError(f"{name}:{index + 1}: {BEGIN} inside another solution block")
        if stripped == END:
            if not lines[index].startswith(indent + END):
                raise TemplateError(
                    f"{name}:{index + 1}: {END} must have the indentation of its {BEGIN} "
                    f"(line {begin + 1})"
                )
            return index
    raise TemplateError(f"{name}:{begin + 1}: {BEGIN} is never closed by {END}")


def _todo_text(block: list[str], indent: str, where: str) -> str:
    """The text of the ``# TODO:`` comment that opens a block (joined over its lines)."""
    if not block or not block[0].startswith(indent + TODO):
        raise TemplateError(
            f"{where}: a solution block must start with a '{TODO} ...' line telling the "
            "student what to write"
        )
    words = [block[0].strip()[len(TODO) :].strip()]
    for line in block[1:]:
        stripped = line.strip()
        if not stripped.startswith("#") or stripped.startswith(TODO):
            break
        words.append(stripped.lstrip("#").strip())
    text = " ".join(word for word in words if word)
    if not text:
        raise TemplateError(f"{where}: the {TODO} comment is empty")
    return text


def _raise_lines(indent: str, message: str) -> list[str]:
    """``raise NotImplementedError(message)``, split over lines as the formatter does."""
    one_line = f"{indent}raise NotImplementedError({_quoted(message)})"
    if len(one_line) <= LINE_LENGTH:
        return [one_line]
    inner = indent + "    "
    width = LINE_LENGTH - len(inner) - 2  # room for the quotes
    pieces = textwrap.wrap(message, width=width, drop_whitespace=False, break_long_words=False)
    pieces = [piece for piece in pieces if piece]
    pieces[-1] = pieces[-1].rstrip()
    return [
        f"{indent}raise NotImplementedError(",
        *(f"{inner}{_quoted(piece)}" for piece in pieces),
        f"{indent})",
    ]


def _quoted(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _interface(tree: ast.Module) -> list[tuple[str, str, str | None]]:
    """(qualified name, signature, docstring) of every module-level or class-level definition."""
    found = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                returns = ast.unparse(child.returns) if child.returns else ""
                signature = f"({ast.unparse(child.args)}) -> {returns}"
                found.append((prefix + child.name, signature, ast.get_docstring(child)))
            elif isinstance(child, ast.ClassDef):
                bases = ", ".join(ast.unparse(base) for base in child.bases)
                found.append((prefix + child.name, f"({bases})", ast.get_docstring(child)))
                visit(child, f"{prefix}{child.name}.")

    visit(tree, "")
    return found


def _check_same_interface(solution: str, template: str, name: str) -> None:
    """The template must compile and keep every signature and docstring of the solution."""
    try:
        template_tree = ast.parse(template)
    except SyntaxError as error:
        raise TemplateError(f"{name}: the template does not compile: {error}") from error
    ours, theirs = _interface(ast.parse(solution)), _interface(template_tree)
    if ours != theirs:
        missing = [item[0] for item in ours if item not in theirs]
        raise TemplateError(
            f"{name}: the template changes the interface of {', '.join(missing) or 'the module'}; "
            "put solution blocks inside function bodies only"
        )
