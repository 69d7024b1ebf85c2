"""Process-wide settings are made by the command line, never by importing msdlab."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from msdlab import cli


def test_importing_msdlab_sets_no_thread_policy() -> None:
    env = {key: value for key, value in os.environ.items() if key != "OMP_WAIT_POLICY"}
    code = "import os, msdlab, msdlab.compiled; print(os.environ.get('OMP_WAIT_POLICY'))"
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "None"


def test_the_command_line_sets_it_unless_the_user_did(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("OMP_WAIT_POLICY", raising=False)
    cli.configure_process()
    assert os.environ["OMP_WAIT_POLICY"] == "PASSIVE"
    monkeypatch.setenv("OMP_WAIT_POLICY", "ACTIVE")
    cli.configure_process()
    assert os.environ["OMP_WAIT_POLICY"] == "ACTIVE"
