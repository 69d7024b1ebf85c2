"""``msdlab handin``: pack your task files into a small zip file to hand in.

The grader reads the task files ``task1.py`` ... ``task5.py`` of your ``assignments/`` and
nothing else, so the zip holds exactly those (as ``assignments/taskN.py``): no virtual
environment, notebooks or outputs. It says what it packed, warns about a task that is
missing or still has parts of its template to write (a ``raise NotImplementedError("Task
N: ...")``), and how to hand the zip in. The zip is what the grader reads as it is.
"""

from __future__ import annotations

import argparse
import re
import zipfile
from pathlib import Path

from ..course import TASKS
from ..course.loader import DEFAULT, course_root

ARCHIVE = "handin.zip"
"""The zip's name, in the course folder, unless --out names another."""

TO_DO = re.compile(r"raise\s+NotImplementedError\(\s*[rbuf]*['\"]+\s*Task\s+\d")
"""A part of a template still to write: ``raise NotImplementedError("Task N: ...")``."""

HOW = """\
Hand it in as your course says (the README's "Handing in"): upload {zip} (Gradescope,
a learning platform, e-mail), or hand in your assignments/ folder itself, or commit and
push your task files to your course repository (git add assignments/task*.py)."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "handin", help="pack your task files into a zip file to hand in", description=__doc__
    )
    parser.add_argument(
        "--impl",
        type=Path,
        default=None,
        help="folder of your task1.py ... task5.py (default: the assignments/ of the course "
        "folder you are in)",
    )
    parser.add_argument(
        "--out", type=Path, default=None, help=f"the zip to write (default: {ARCHIVE} there)"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    root = course_root(Path.cwd())
    folder = (args.impl or root / DEFAULT).expanduser().resolve()
    if not folder.is_dir():
        raise FileNotFoundError(
            f"no folder of task files at {folder}: run msdlab handin in your course folder "
            "(the one holding assignments/), or give --impl DIR"
        )
    files = [folder / f"task{task}.py" for task in TASKS if (folder / f"task{task}.py").is_file()]
    if not files:
        raise FileNotFoundError(f"{folder} holds none of task1.py ... task5.py: nothing to hand in")
    out = (args.out or root / ARCHIVE).expanduser().resolve()
    pack(files, out)
    print(f"msdlab handin: wrote {out} ({out.stat().st_size:,} bytes) holding")
    for path in files:
        print(f"  {DEFAULT}/{path.name}  ({path.stat().st_size:,} bytes){to_do_note(path)}")
    missing = [f"task{task}.py" for task in TASKS if not (folder / f"task{task}.py").is_file()]
    if missing:
        print(f"warning: {', '.join(missing)} missing from {folder}: those tasks get no points")
    print(HOW.format(zip=out.name))
    return 0


def pack(files: list[Path], out: Path) -> None:
    """Write the zip ``out`` holding ``files`` as ``assignments/NAME`` (what the grader reads
    from a zip: its ``assignments/`` folder)."""
    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_name(out.name + ".part")
    with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as bundle:
        for path in files:
            bundle.write(path, f"{DEFAULT}/{path.name}")
    partial.replace(out)


def to_do_note(path: Path) -> str:
    """'  warning: 2 parts still the template's, to write (line 41, 77)' for a task file
    with parts of its template left to write; '' for one without."""
    text = path.read_text(encoding="utf-8", errors="replace")
    left = [text.count("\n", 0, found.start()) + 1 for found in TO_DO.finditer(text)]
    if not left:
        return ""
    parts = "1 part" if len(left) == 1 else f"{len(left)} parts"
    where = ", ".join(map(str, left))
    return f"\n    warning: {parts} still the template's, to write (line {where})"
