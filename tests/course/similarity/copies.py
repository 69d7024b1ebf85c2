"""A planted class for the similarity report: one student's work copied two ways, and
honest solutions written independently.

Every submission is the student template ``assignments/taskN.py`` with its answer
functions replaced by a student's (other top-level code of the student, helpers and
imports, goes before the first answer):

- ``original``: the reference solutions;
- ``renamed``: ``original`` with every local variable of the answers renamed;
- ``reordered``: ``original`` with the functions of each file in reverse order;
- ``honest_loops``: the alternatives of ``tests/course/alternatives`` (loops);
- ``honest_masks``: ``tests/course/similarity/honest`` (vectorised: masks, padding, einsum,
  a quaternion, closed forms);
- ``honest_plain``: ``tests/course/similarity/plain`` (plain Python and helpers: np.diff,
  a sparse incidence matrix, a bisecting search, base-3 offsets, velocity form).

The three honest students wrote each task independently of the reference and of each other.
"""

from __future__ import annotations

import ast
import io
import tokenize
from pathlib import Path

from msdlab.course import PROJECT_ROOT, TASKS

HERE = Path(__file__).parent
TEMPLATES = PROJECT_ROOT / "assignments"
COPIES = ("renamed", "reordered")
HONEST = ("original", "honest_loops", "honest_masks", "honest_plain")
RENAMES = {  # how the copier renamed the locals of the answers
    "a": "acc", "axis": "dim", "first": "lower", "second": "upper", "d": "diff",
    "length": "dist", "direction": "unit", "f": "force", "steps": "choices",
    "offsets": "result", "di": "p", "dj": "q", "dk": "r", "index": "ids", "pairs": "links",
    "rest": "natural", "offset": "shift", "found": "joined", "positions": "pts",
    "centroid": "centre", "springs": "edges", "body": "cube", "before": "start_thickness",
    "simulation": "sim", "start": "t0", "wanted": "allowed", "o": "off", "n": "size",
}  # fmt: skip


def write_class(folder: Path) -> dict[str, Path]:
    """Write the planted class into ``folder``/STUDENT/assignments; return the folders."""
    students = {
        "original": {t: strip_markers(PROJECT_ROOT / "solutions" / f"task{t}.py") for t in TASKS},
        "honest_loops": {t: answered(t, HERE.parent / "alternatives") for t in TASKS},
        "honest_masks": {t: answered(t, HERE / "honest") for t in TASKS},
        "honest_plain": {t: answered(t, HERE / "plain") for t in TASKS},
    }
    students["renamed"] = {t: renamed(s) for t, s in students["original"].items()}
    students["reordered"] = {t: reordered(s) for t, s in students["original"].items()}
    folders = {}
    for student, files in students.items():
        folders[student] = folder / student / "assignments"
        folders[student].mkdir(parents=True)
        for task, source in files.items():
            (folders[student] / f"task{task}.py").write_text(source, encoding="utf-8")
    return folders


def strip_markers(solution: Path) -> str:
    """A solution file as a student would hand it in: the solution markers and hints gone."""
    kept, hint = [], False
    for line in solution.read_text(encoding="utf-8").splitlines(keepends=True):
        text = line.strip()
        if text.startswith("### BEGIN SOLUTION") or text.startswith("### END SOLUTION"):
            hint = text.startswith("### BEGIN")
            continue
        if hint and text.startswith("#"):
            continue
        hint = False
        kept.append(line)
    return "".join(kept)


def functions(tree: ast.Module) -> list[ast.FunctionDef]:
    return [node for node in tree.body if isinstance(node, ast.FunctionDef)]


def span(node: ast.stmt) -> tuple[int, int]:
    """First and last line (0-based, end exclusive) of a top-level statement."""
    first = min([node.lineno, *(d.lineno for d in getattr(node, "decorator_list", []))])
    return first - 1, node.end_lineno


def answered(task: int, student_folder: Path) -> str:
    """The template of ``task`` with the functions of the student's file put in."""
    template = (TEMPLATES / f"task{task}.py").read_text(encoding="utf-8")
    student_file = student_folder / f"task{task}.py"
    if not student_file.exists():
        return template
    student = student_file.read_text(encoding="utf-8")
    lines, theirs = template.splitlines(keepends=True), student.splitlines(keepends=True)
    student_tree, template_tree = ast.parse(student), ast.parse(template)
    given = {f.name: f for f in functions(template_tree)}
    template_text = set(template.splitlines())
    constants = set().union(*(assigns(node) for node in template_tree.body))
    extra = []
    for node in student_tree.body[1:]:  # the docstring first
        start, end = span(node)
        text = "".join(theirs[start:end])
        if isinstance(node, ast.FunctionDef) and node.name in given:
            begin, stop = span(given[node.name])
            lines[begin:stop] = [text] + [""] * (stop - begin - 1)
        elif not (set(text.splitlines()) <= template_text or redefines(node, constants)):
            extra.append(text)
    answers = [
        f for f in functions(template_tree) if f.name in {n.name for n in functions(student_tree)}
    ]
    first = span(answers[0])[0]
    lines[first] = "".join(extra) + "\n\n" + lines[first] if extra else lines[first]
    return "".join(lines)


def assigns(node: ast.stmt) -> set[str]:
    """The names a top-level assignment sets (none for other statements)."""
    if not isinstance(node, ast.Assign):
        return set()
    return {n.id for t in node.targets for n in ast.walk(t) if isinstance(n, ast.Name)}


def redefines(node: ast.stmt, constants: set[str]) -> bool:
    """Whether ``node`` only sets again constants that the template sets."""
    return isinstance(node, ast.Assign) and assigns(node) <= constants


def renamed(source: str) -> str:
    """``source`` with the local variables of every function renamed by `RENAMES`."""
    lines = source.splitlines(keepends=True)
    for node in functions(ast.parse(source)):
        params = {a.arg for a in ast.walk(node.args) if isinstance(a, ast.arg)}
        stored = {
            n.id for n in ast.walk(node) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)
        }
        names = {n: RENAMES[n] for n in stored - params if n in RENAMES}
        start, end = span(node)
        lines[start:end] = rename_tokens("".join(lines[start:end]), names).splitlines(True)
    return "".join(lines)


def rename_tokens(code: str, names: dict[str, str]) -> str:
    """``code`` with each name in ``names`` replaced, attributes and keywords left alone."""
    tokens = list(tokenize.generate_tokens(io.StringIO(code).readline))
    out, depth = [], 0
    for i, token in enumerate(tokens):
        depth += token.string in "([{" if token.type == tokenize.OP else 0
        depth -= token.string in ")]}" if token.type == tokenize.OP else 0
        after = tokens[i + 1].string if i + 1 < len(tokens) else ""
        before = tokens[i - 1].string if i else ""
        keyword = depth > 0 and after == "=" and before in "(,"
        if token.type == tokenize.NAME and token.string in names and before != "." and not keyword:
            token = token._replace(string=names[token.string])
        out.append(token)
    return tokenize.untokenize(out)


def reordered(source: str) -> str:
    """``source`` with its top-level functions in reverse order (other code where it was)."""
    lines = source.splitlines(keepends=True)
    spans = [span(f) for f in functions(ast.parse(source))]
    texts = ["".join(lines[a:b]) for a, b in spans]
    for (start, end), text in reversed(list(zip(spans, reversed(texts)))):
        lines[start:end] = [text]
    return "".join(lines)
