"""How long is a first `msdlab demo`? A cold run (nothing compiled yet) next to a warm one.

Each run is a fresh ``msdlab demo`` process. A cold run gets an empty numba cache
(``NUMBA_CACHE_DIR`` set to a new temporary folder), as on a machine where msdlab
has never run: it runs on the numpy kernel and compiles the numba kernel in a
background process (`msdlab.commands.first_run`). The benchmark waits for that
process ("compiled ready": seconds from the cold run's start until the cache holds
the loops), then the warm run reuses the folder, as every later run does. Apart from
them, "compiling alone" runs that background process's work in the foreground in an
empty cache (what it costs the machine). The table shows wall-clock seconds and the
CPU seconds the process used (user + system: on a busy machine the wall clock waits
for other work, the CPU time much less), median over the repeats, interleaved.

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

from msdlab.commands.first_run import compiling_lock


def seconds(command: list[str], cache: str) -> tuple[float, float, str]:
    """Wall and CPU seconds of one run of ``command`` with numba's cache in ``cache``, and
    the first line it printed about compiling (or "")."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    env.pop("MSDLAB_KERNEL", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    said = result.stdout.splitlines() + result.stderr.splitlines()
    note = next((line for line in said if "compil" in line), "")
    return wall, cpu, note


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--size", type=int, default=6, help="the demo's cube edge (its default)")
    args = parser.parse_args()

    runs: dict[str, list[tuple[float, float]]] = {"cold": [], "warm": [], "compiling alone": []}
    ready = []
    notes = set()
    for _ in range(args.repeats):
        with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
            demo = [sys.executable, "-m", "msdlab", "demo", "--out", out, "--size", str(args.size)]
            started = time.perf_counter()
            for kind in ("cold", "warm"):
                wall, cpu, note = seconds(demo, cache)
                runs[kind].append((wall, cpu))
                notes.add((kind, note))
                if kind == "cold":
                    with compiling_lock(wait=True, cache=cache):  # the background compiling
                        ready.append(time.perf_counter() - started)
        with tempfile.TemporaryDirectory() as cache:
            compiling = [sys.executable, "-m", "msdlab.commands.first_run"]
            runs["compiling alone"].append(seconds(compiling, cache)[:2])
    print("| run | wall s (median) | CPU s (median) | wall s of each |")
    print("| --- | --- | --- | --- |")
    for kind, times in runs.items():
        walls, cpus = zip(*times)
        spread = ", ".join(f"{wall:.1f}" for wall in walls)
        print(
            f"| {kind} | {statistics.median(walls):.1f} | {statistics.median(cpus):.1f} "
            f"| {spread} |"
        )
    print(f"compiled ready {statistics.median(ready):.1f} s after the cold run started")
    for kind, note in sorted(notes):
        print(f"{kind}: {note or '(no line about compiling)'}")


if __name__ == "__main__":
    main()
