"""How much memory does the intake take for a small repository of one huge object?

Workload: a git repository whose one commit holds task1.py and a task2.py of SIZE bytes
of zeros, its objects in one pack (a few hundred kB on disk), taken in by
``intake.Intake.add`` in a fresh process. Prints the pack's size, the row's notes and
the process's peak resident memory before and after the intake (``ru_maxrss``): the
intake reads the object's size from its header and leaves it out unread, so the peak
should not grow with SIZE.

    python benchmarks/intake_memory.py                    # 300 MB of zeros
    python benchmarks/intake_memory.py --size 50000000
"""

from __future__ import annotations

import argparse
import resource
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

from dulwich.objects import Blob, Commit, Tree
from dulwich.repo import Repo


def repository(folder: Path, size: int) -> int:
    """The repository of the workload at ``folder``; the pack's size in bytes."""
    repo = Repo.init(str(folder), mkdir=True)
    huge, small = Blob.from_string(bytes(size)), Blob.from_string(b"x = 1\n")
    inner, top = Tree(), Tree()
    inner.add(b"task1.py", 0o100644, small.id)
    inner.add(b"task2.py", 0o100644, huge.id)
    top.add(b"assignments", stat.S_IFDIR, inner.id)
    commit = Commit()
    commit.tree, commit.parents, commit.message = top.id, [], b"work\n"
    commit.author = commit.committer = b"Student <student@example.org>"
    commit.author_time = commit.commit_time = 1_800_000_000
    commit.author_timezone = commit.commit_timezone = 0
    repo.object_store.add_objects([(obj, None) for obj in (huge, small, inner, top, commit)])
    repo.refs[b"refs/heads/master"] = commit.id
    return sum(path.stat().st_size for path in (folder / ".git/objects/pack").glob("*.pack"))


def take_in(folder: Path) -> None:
    """Take ``folder`` in and print the notes and the peak memory (run in its own process)."""
    from msdlab.instructor import intake

    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with intake.Intake() as found:
        entry = found.add("mallory", folder)
        print(f"problem: {entry.problem}; notes: {entry.notes}")
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(f"peak resident memory: {before / 1024:.0f} MB before the intake, "
          f"{after / 1024:.0f} MB after")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=300_000_000, help="bytes of zeros")
    parser.add_argument("--build", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--take-in", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.build:
        print(f"pack: {repository(args.build, args.size)} bytes for a {args.size}-byte object")
    elif args.take_in:
        take_in(args.take_in)
    else:  # each step in a process of its own: a child starts with its parent's peak memory
        with tempfile.TemporaryDirectory() as scratch:
            folder = Path(scratch) / "mallory"
            for step in ("--build", "--take-in"):
                command = [sys.executable, __file__, step, str(folder), "--size", str(args.size)]
                subprocess.run(command, check=True)


if __name__ == "__main__":
    main()
