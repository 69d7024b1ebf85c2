"""Fixtures of the course and grading tests."""

from __future__ import annotations

import shutil
import tempfile
import textwrap
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from msdlab.instructor.judging.sandbox import RemoteImplementation


@pytest.fixture(scope="module")
def serve_task() -> Iterator[Callable[[str, str], RemoteImplementation]]:
    """``serve_task(file, source)``: a sandbox serving a submission of that one task file,
    closed and removed after the module's tests."""
    served: list[tuple[RemoteImplementation, Path]] = []

    def serve(file: str, source: str) -> RemoteImplementation:
        folder = Path(tempfile.mkdtemp(prefix="msdlab-served-"))  # readable by the sandbox user
        folder.chmod(0o755)
        (folder / file).write_text(textwrap.dedent(source))
        implementation = RemoteImplementation(folder, timeout=20.0, memory_bytes=1024 * 2**20)
        served.append((implementation, folder))
        return implementation

    yield serve
    for implementation, folder in served:
        implementation.close()
        shutil.rmtree(folder)
