"""The Python examples of the documentation and the README run as written.

Each page's ```python blocks run in order, in one namespace, in a fresh folder, with no
display. A block that starts with ``# Needs a display`` or ``# Sketch`` is left out.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
SKIP = ("# Needs a display", "# Sketch")


def python_blocks(page: Path) -> list[str]:
    blocks = re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)
    return [block for block in blocks if not block.startswith(SKIP)]


PAGES = [ROOT / "README.md"] + sorted(
    page for page in DOCS.rglob("*.md") if "_build" not in page.parts and python_blocks(page)
)


def test_the_readme_and_the_engine_pages_show_python():
    assert python_blocks(ROOT / "README.md")
    assert DOCS / "engine" / "example.md" in PAGES
    assert DOCS / "engine" / "scenes.md" in PAGES


@pytest.mark.parametrize("page", PAGES, ids=lambda page: str(page.relative_to(ROOT)))
def test_page_examples_run(page, tmp_path):
    """The page's blocks as one script; files it names (.png, .gif, ...) are written."""
    script = "\n".join(python_blocks(page))
    subprocess.run(
        [sys.executable, "-c", script],
        cwd=tmp_path,
        env={"MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)},
        check=True,
        timeout=600,
    )
    for name in re.findall(r'"([\w.-]+\.(?:png|pdf|svg|gif|html))"', script):
        assert (tmp_path / name).stat().st_size > 1000, name


def test_the_one_screen_cube_keeps_nine_tenths_of_its_height_on_the_ground():
    """The engine's one-screen example: the jelly cube it drops holds its shape."""
    (code,) = python_blocks(DOCS / "engine" / "example.md")
    scope: dict = {}
    exec(compile(code, "docs/engine/example.md", "exec"), scope)
    cube, trajectory = scope["cube"], scope["trajectory"]
    height = np.ptp(trajectory.positions[:, :, 1], axis=1)
    assert height[-1] >= 0.9 * height[0]  # measured: 96 %
    assert trajectory.positions[-1, :, 1].min() >= 0.0  # on the ground, not through it
    assert np.abs(trajectory.energies.kinetic[-1]) < 0.01 * trajectory.energies.total[0]
    assert len(cube) == 1000
