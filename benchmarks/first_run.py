"""How long is a first `msdlab demo`? A cold run (nothing compiled yet) next to a warm one.

Each run is a fresh ``msdlab demo`` process. A cold run gets an empty numba cache
(``NUMBA_CACHE_DIR`` set to a new temporary folder), as on a machine where msdlab
has never run; the warm run after it reuses that folder, as every later run does.
The table shows wall-clock seconds and the CPU seconds the process used (user +
system: on a busy machine the wall clock waits for other work, the CPU time much
less), median over the repeats, cold and warm interleaved.

    python benchmarks/first_run.py                 # 3 repeats
    python benchmarks/first_run.py --repeats 5 --size 6
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time


def demo_seconds(cache: str, out: str, size: int) -> tuple[float, float, str]:
    """Wall and CPU seconds of one ``msdlab demo`` with numba's cache in ``cache``, and the
    first line it printed about compiling (or "")."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    command = [sys.executable, "-m", "msdlab", "demo", "--out", out, "--size", str(size)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    said = [line for line in result.stdout.splitlines() + result.stderr.splitlines()]
    note = next((line for line in said if "compil" in line), "")
    return wall, cpu, note


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--size", type=int, default=6, help="the demo's cube edge (its default)")
    args = parser.parse_args()

    runs: dict[str, list[tuple[float, float]]] = {"cold": [], "warm": []}
    notes = set()
    for _ in range(args.repeats):
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
            for kind in ("cold", "warm"):
                wall, cpu, note = demo_seconds(cache, out, args.size)
                runs[kind].append((wall, cpu))
                notes.add((kind, note))
    print("| run | wall s (median) | CPU s (median) | runs |")
    print("| --- | --- | --- | --- |")
    for kind, times in runs.items():
        walls, cpus = zip(*times)
        spread = ", ".join(f"{wall:.1f}" for wall in walls)
        print(
            f"| {kind} | {statistics.median(walls):.1f} | {statistics.median(cpus):.1f} "
            f"| {spread} |"
        )
    for kind, note in sorted(notes):
        print(f"{kind}: {note or '(no line about compiling)'}")


if __name__ == "__main__":
    main()
