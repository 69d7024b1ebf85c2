"""A first run on a machine says, before it compiles the engine, that it does and how long;
`msdlab demo` and `msdlab run` run it on the numpy kernel and compile in the background."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import time

from msdlab.commands.first_run import NOTE, compiling_lock
from msdlab.commands.progress import COMPILING, STARTING, step_bar

ASK = "from msdlab.engine.backends.choice import compiling_first; print(compiling_first())"


def test_a_run_that_compiles_says_so_before_the_first_step() -> None:
    stream = io.StringIO()
    with step_bar(100, "run", file=stream, note_after=0.05, compiling=True) as bar:
        assert stream.getvalue().startswith(COMPILING + "\n")
        time.sleep(0.3)
        bar(100)
    assert stream.getvalue().count(COMPILING) == 1
    assert STARTING not in stream.getvalue()  # said once, not twice


def test_an_empty_numba_cache_means_compiling(tmp_path) -> None:
    def asked(**env: str) -> str:
        settings = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), **env}
        command = [sys.executable, "-c", ASK]
        return subprocess.run(command, env=settings, capture_output=True, text=True).stdout

    assert asked() == "True\n"
    assert asked(MSDLAB_KERNEL="numpy") == "False\n"  # nothing to compile


def test_a_first_demo_runs_at_once_and_leaves_the_engine_compiled(tmp_path) -> None:
    cache = tmp_path / "numba-cache"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    env.pop("MSDLAB_KERNEL", None)
    demo = ["demo", "--out", str(tmp_path), "--size", "3", "--steps", "20", "--frames", "2"]
    run = ["run", "two-particles", "--duration", "0.1"]

    def typed(arguments: list[str]) -> subprocess.CompletedProcess:
        command = [sys.executable, "-m", "msdlab", *arguments]
        return subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)

    first = typed(demo)
    assert first.returncode == 0, first.stderr
    assert first.stderr.startswith(NOTE + "\n"), first.stderr
    assert "energy plot:" in first.stdout
    with compiling_lock(wait=True, cache=str(cache)):  # the background process is done
        pass
    assert (
        subprocess.run([sys.executable, "-c", ASK], env=env, capture_output=True, text=True).stdout
        == "False\n"
    )  # nothing left to compile for a demo
    later = typed(run)
    assert later.returncode == 0, later.stderr
    assert NOTE not in later.stderr and COMPILING not in later.stderr
