"""The README's viz snippets, run as scripts, write the files they name."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).parents[2] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
SNIPPETS = [b for b in BLOCKS if "viz." in b and "viz.show" not in b]  # show needs a display


def test_the_readme_has_viz_snippets():
    assert SNIPPETS, "README.md should show how to plot and animate"


@pytest.mark.parametrize("snippet", SNIPPETS)
def test_snippet_writes_the_files_it_names(snippet, tmp_path):
    names = re.findall(r'"([\w.-]+\.(?:png|pdf|svg|gif|html))"', snippet)
    assert names, "a viz snippet should save what it draws"
    subprocess.run(
        [sys.executable, "-c", snippet],
        cwd=tmp_path,
        env={"MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)},
        check=True,
        timeout=300,
    )
    for name in names:
        assert (tmp_path / name).stat().st_size > 1000, name
