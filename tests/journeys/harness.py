"""Walking a person's path through msdlab: a fresh virtual environment, commands typed at a
shell, what they print.

The journey tests import it (``from harness import ...``: pytest puts this folder on the
path):

- `typed`: a command line run as written (bash, a virtual environment's ``bin/`` first
  on ``PATH``); it returns what it printed and its exit status.
- `Terminal`: a person's shell in a fresh virtual environment; `Terminal.type` is `typed`
  there.
- `Session`: a person's shell that starts on the system's Python and uses the virtual
  environment a typed ``python3 -m venv X && . X/bin/activate`` makes.
- `quick_start`: the command lines of a README's quick-start block, as written.
- `release`: ``msdlab release`` of this checkout, as an instructor runs it.

The environment is new, but it borrows the packages of the one running the tests (a
``.pth`` file, as the student bundle's own test does): ``pip install`` finds every
dependency installed and downloads nothing, while msdlab itself is installed from the
folder the person is in, so the commands prove that what they install works there.
"""

from __future__ import annotations

import os
import re
import site
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
"""The course checkout under test."""


@dataclass
class Typed:
    """A command line a person typed, its exit status and what it printed (both streams)."""

    command: str
    status: int
    output: str

    def __str__(self) -> str:
        return f"$ {self.command}\n{self.output}(exit status {self.status})"


def typed(command: str, cwd: Path, venv: Path | None, timeout: float = 600) -> Typed:
    """``command`` as typed at a shell prompt in ``cwd`` with the virtual environment
    ``venv`` activated (its ``bin/`` first on ``PATH``; None: the system's Python, no
    environment), and no msdlab, pytest or Python settings of the process running the
    tests: what it printed, its exit status."""
    inherited = {
        key: value
        for key, value in os.environ.items()
        if not key.startswith(("MSDLAB_", "PYTEST_", "PYTHON")) and key != "VIRTUAL_ENV"
    }
    # the environment running the tests is not the person's
    tests = {Path(os.environ["VIRTUAL_ENV"]) / "bin"} if "VIRTUAL_ENV" in os.environ else set()
    if sys.prefix != sys.base_prefix:
        tests.add(Path(sys.executable).parent)
    system = [p for p in inherited.get("PATH", "").split(os.pathsep) if Path(p) not in tests]
    path = os.pathsep.join(([str(venv / "bin")] if venv else []) + system)
    settings = {"VIRTUAL_ENV": str(venv)} if venv else {}
    done = subprocess.run(
        ["bash", "-c", command],
        cwd=cwd,
        env={**inherited, "PATH": path, **settings},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=timeout,
        check=False,
    )
    return Typed(command, done.returncode, done.stdout)


def borrow(venv: Path) -> None:
    """Let the virtual environment ``venv`` import the packages of the Python running the
    tests, after its own: pip then finds every dependency installed and downloads nothing."""
    python = venv / "bin" / "python"
    packages = subprocess.check_output(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], text=True
    ).strip()
    (Path(packages) / "borrowed.pth").write_text("\n".join(site.getsitepackages()) + "\n")


ACTIVATE = re.compile(r"^python3 -m venv (\S+) && (?:source|\.) \1/bin/activate$")
"""A command line that makes a virtual environment and activates it, as the pages write it."""


class Session:
    """A person's terminal, commands typed one after another: no environment at first (the
    system's ``python3``); a line ``python3 -m venv X && . X/bin/activate`` makes ``X`` as
    typed (with `borrow`) and the environment of every command after it."""

    def __init__(self, venv: Path | None = None) -> None:
        self.venv = venv

    def type(self, command: str, cwd: Path, timeout: float = 600) -> Typed:
        """Run ``command`` as typed at the prompt in ``cwd``; what it printed, its status."""
        activate = ACTIVATE.match(command.strip())
        if activate is None:
            return typed(command, cwd, self.venv, timeout)
        made = typed(f"python3 -m venv {activate[1]}", cwd, self.venv, timeout)
        if made.status == 0:
            self.venv = (cwd / activate[1]).resolve()
            borrow(self.venv)
        return Typed(command, made.status, made.output)


class Terminal:
    """A shell in a fresh virtual environment at ``home / 'venv'``."""

    def __init__(self, home: Path) -> None:
        self.home = Path(home)
        self.venv = self.home / "venv"
        subprocess.run([sys.executable, "-m", "venv", str(self.venv)], check=True)
        borrow(self.venv)

    @property
    def python(self) -> Path:
        """The environment's Python."""
        return self.venv / "bin" / "python"

    def type(self, command: str, cwd: Path, timeout: float = 600) -> Typed:
        """Run ``command`` as typed at the prompt in ``cwd``; what it printed, its status."""
        return typed(command, cwd, self.venv, timeout)


def quick_start(readme: Path) -> list[str]:
    """The command lines of the first ``bash`` block under a README's "Quick start" heading."""
    text = readme.read_text(encoding="utf-8")
    section = re.search(r"^#+ Quick start\s*$(.*?)(?=^#+ |\Z)", text, re.M | re.S)
    block = section and re.search(r"```bash\n(.*?)```", section[1], re.S)
    if not block:
        raise ValueError(f"{readme} has no bash block under a 'Quick start' heading")
    lines = [line.split("  #")[0].strip() for line in block[1].splitlines()]
    return [line for line in lines if line and not line.startswith("#")]


def release(out: Path, course: Path = ROOT) -> Path:
    """The student bundle of ``course``, made by ``msdlab release`` as an instructor types it."""
    subprocess.run(
        [sys.executable, "-m", "msdlab", "release", str(out), "--course", str(course)],
        cwd=out.parent,
        check=True,
        capture_output=True,
    )
    return out
