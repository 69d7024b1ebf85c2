"""How long does a student wait for ``msdlab check 2``?

The loop a student runs fifty times a week: ``msdlab check 2`` in the course folder,
on the reference answers (every check runs to the end) and on the templates (every
check stops at the first call). Each command runs as the student types it, in a
fresh process from the course folder ``--root`` (default: this checkout; its own
``msdlab/`` is imported, whichever is installed), after one run that writes the
bytecode caches (a warm machine; ``PYTHONDONTWRITEBYTECODE`` is left out, as a
student's shell does not set it). ``--root A --root B`` times two checkouts
interleaved, e.g. a branch against main.

The machine is shared, so the yardstick runs interleaved with them: a fresh Python
that imports numpy, the least any check run costs. Reported: median and range of the
seconds each took, and the median of each run over the yardstick next to it.

    python benchmarks/check_speed.py [--repeats 7] [--root PATH ...]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET = 2.0  # seconds: the most a student should wait for the checks of one task

COMMANDS = {
    "yardstick (python -c 'import numpy')": [sys.executable, "-c", "import numpy"],
    "msdlab check 2 --impl solutions": [
        *(sys.executable, "-m", "msdlab", "check", "2", "--impl", "solutions"),
    ],
    "msdlab check 2 (the templates)": [
        *(sys.executable, "-m", "msdlab", "check", "2", "--impl", "assignments"),
    ],
}


def seconds(command: list[str], root: Path) -> float:
    """Wall-clock seconds of one run of ``command`` in ``root`` with ``root``'s own msdlab
    (its output discarded)."""
    environment = {**os.environ, "PYTHONPATH": str(root)}
    for name in ("MSDLAB_IMPL", "PYTHONDONTWRITEBYTECODE"):  # as in a student's shell
        environment.pop(name, None)
    started = time.perf_counter()
    subprocess.run(
        command, cwd=root, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument(
        "--root", type=Path, action="append", help="a course checkout to time (repeatable)"
    )
    args = parser.parse_args()
    roots = [root.resolve() for root in args.root or [ROOT]]
    runs = [(root, name, command) for root in roots for name, command in COMMANDS.items()]
    for root, _, command in runs:  # warm: bytecode caches written, files in the page cache
        seconds(command, root)
    times: dict[tuple[Path, str], list[float]] = {(root, name): [] for root, name, _ in runs}
    for _ in range(args.repeats):
        for root, name, command in runs:
            times[root, name].append(seconds(command, root))
    print(f"{args.repeats} interleaved runs of each")
    for root in roots:
        print(root)
        yardstick = times[root, next(iter(COMMANDS))]
        for name in COMMANDS:
            values = times[root, name]
            ratio = statistics.median(v / y for v, y in zip(values, yardstick))
            print(
                f"  {name:38s} median {statistics.median(values):5.2f} s "
                f"(range {min(values):.2f}-{max(values):.2f} s), {ratio:4.1f}× the yardstick"
            )
    print(f"target: the checks of one task within {TARGET:g} s on a warm, quiet machine")


if __name__ == "__main__":
    main()
