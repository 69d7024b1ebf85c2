"""A first run on a machine says, before it compiles the engine, that it does and how long."""

from __future__ import annotations

import io
import os
import subprocess
import sys
import time

from msdlab.commands.progress import COMPILING, STARTING, step_bar

ASK = "from msdlab.spring_kernel import compiling_first; print(compiling_first())"


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
