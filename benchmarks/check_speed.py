"""How long does a student wait for ``msdlab check 2``?

The loop a student runs fifty times a week: ``msdlab check 2`` in the course folder,
on the templates (every check stops at the first call) and on the reference answers
(every check runs to the end). Each command runs as the student types it, in a fresh
process (``PYTHONDONTWRITEBYTECODE`` is left out, as a student's shell does not set it).

Two places to time it:

- ``--release`` (as the student meets it): ``msdlab release`` builds a release in a
  fresh folder, a fresh virtual environment gets it as its README says
  (``pip install -e ".[grade]"``, the packages from pip's configured index), and the
  checks run there with an empty user cache folder: the *first* run (nothing of the
  release compiled yet), then the later ones. ``--keep DIR`` builds it in DIR and keeps
  it; given again, the release there is timed without building it anew.
- ``--root PATH`` (default: this checkout, its own ``msdlab/`` imported): a warm
  checkout, after one run; ``--root A --root B`` times two checkouts interleaved, e.g. a
  branch against main.

The machine may be shared, so the yardstick runs interleaved with them: a fresh Python
that imports numpy, the least any check run costs. Reported: median and range of the
seconds each took (wall clock), the median of each run over the yardstick next to it,
the median CPU seconds (user + system, of the command and its children: what the
command costs whatever else runs), and the load average.

    python benchmarks/check_speed.py --release [--keep DIR] [--repeats 7]
    python benchmarks/check_speed.py [--repeats 7] [--root PATH ...]
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
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGET = 1.5  # seconds: the most a student should wait for the checks of one task


def commands(python: Path, solutions: Path) -> dict[str, list[str]]:
    """The commands timed, run by ``python`` (a checkout's or a release's)."""
    check = [str(python), "-m", "msdlab", "check", "2"]
    return {
        "yardstick (python -c 'import numpy')": [str(python), "-c", "import numpy"],
        "msdlab check 2 (the templates)": check,
        "msdlab check 2 --impl solutions": [*check, "--impl", str(solutions)],
    }


def student_environment(extra: dict[str, str]) -> dict[str, str]:
    """This process's environment as a student's shell has it, with ``extra``."""
    environment = {**os.environ, **extra}
    for name in ("MSDLAB_IMPL", "PYTHONDONTWRITEBYTECODE", "PYTHONPYCACHEPREFIX", "VIRTUAL_ENV"):
        environment.pop(name, None)
    return environment


def timed(command: list[str], cwd: Path, environment: dict[str, str]) -> tuple[float, float]:
    """Wall-clock and CPU seconds (user + system, with its children) of one run of
    ``command`` in ``cwd`` (its output discarded)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    subprocess.run(
        command, cwd=cwd, env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def build_release(folder: Path) -> Path:
    """A release in ``folder`` installed in its own virtual environment as its README says;
    the environment's Python."""
    python = folder / ".venv" / "bin" / "python"
    if python.exists():
        return python
    release = [sys.executable, "-m", "msdlab", "release", str(folder)]
    subprocess.run(release, cwd=ROOT.parent, check=True, stdout=subprocess.DEVNULL)
    base = getattr(sys, "_base_executable", sys.executable)
    subprocess.run([base, "-m", "venv", str(folder / ".venv")], check=True)
    install = [str(python), "-m", "pip", "install", "-q", "-e", ".[grade]"]
    subprocess.run(install, cwd=folder, check=True, env=student_environment({}))
    return python


def report(label: str, times: dict[str, list[tuple[float, float]]]) -> None:
    """Median, range, ratio to the yardstick and CPU seconds of each command."""
    print(label)
    yardstick = [wall for wall, _ in next(iter(times.values()))]
    for name, values in times.items():
        walls, cpus = [wall for wall, _ in values], [cpu for _, cpu in values]
        ratio = statistics.median(w / y for w, y in zip(walls, yardstick))
        print(
            f"  {name:38s} median {statistics.median(walls):5.2f} s "
            f"(range {min(walls):.2f}-{max(walls):.2f} s), {ratio:4.1f}× the yardstick, "
            f"CPU {statistics.median(cpus):.2f} s"
        )


def interleaved(
    runs: dict[str, tuple[list[str], Path, dict[str, str]]], repeats: int
) -> dict[str, list[tuple[float, float]]]:
    """``repeats`` rounds, each running every command once in turn."""
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, (command, cwd, environment) in runs.items():
            times[name].append(timed(command, cwd, environment))
    return times


def time_release(folder: Path, repeats: int) -> None:
    """The first and the later runs in a fresh release (see the module docstring)."""
    python = build_release(folder)
    with tempfile.TemporaryDirectory(prefix="msdlab-student-cache-") as cache:
        environment = student_environment({"XDG_CACHE_HOME": cache, "PATH": _path(python)})
        named = commands(python, ROOT / "solutions")
        check = named["msdlab check 2 (the templates)"]
        wall, cpu = timed(check, folder, environment)
        print(f"release in {folder}: load average {_load()}")
        print(f"  first msdlab check 2 (the templates)   {wall:5.2f} s, CPU {cpu:.2f} s")
        runs = {name: (command, folder, environment) for name, command in named.items()}
        report(f"later runs ({repeats} interleaved)", interleaved(runs, repeats))


def time_checkouts(roots: list[Path], repeats: int) -> None:
    """Warm checkouts, interleaved (see the module docstring)."""
    runs = {}
    for root in roots:
        environment = student_environment({"PYTHONPATH": str(root)})
        for name, command in commands(Path(sys.executable), root / "solutions").items():
            runs[f"{root}: {name}"] = (command, root, environment)
    for command, cwd, environment in runs.values():  # bytecode written, files in the page cache
        timed(command, cwd, environment)
    times = interleaved(runs, repeats)
    for root in roots:
        mine = {
            name.split(": ", 1)[1]: v for name, v in times.items() if name.startswith(f"{root}:")
        }
        report(str(root), mine)


def _path(python: Path) -> str:
    """PATH with the environment of ``python`` first, as an activated one has it."""
    return f"{python.parent}{os.pathsep}{os.environ.get('PATH', '')}"


def _load() -> str:
    return " ".join(f"{value:.1f}" for value in os.getloadavg())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--release", action="store_true", help="time it in a fresh release")
    parser.add_argument("--keep", type=Path, default=None, help="with --release: build it here")
    parser.add_argument(
        "--root", type=Path, action="append", help="a course checkout to time (repeatable)"
    )
    args = parser.parse_args()
    if args.release:
        if args.keep is not None:
            time_release(args.keep.resolve(), args.repeats)
        else:
            with tempfile.TemporaryDirectory(prefix="msdlab-release-") as scratch:
                time_release(Path(scratch) / "course", args.repeats)
    else:
        time_checkouts([root.resolve() for root in args.root or [ROOT]], args.repeats)
    print(f"load average at the end {_load()}")
    print(f"target: the checks of one task within {TARGET:g} s on a quiet machine")


if __name__ == "__main__":
    main()
