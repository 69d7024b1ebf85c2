"""The README's "engine in one screen" example: the jelly cube it drops holds its shape."""

import re
from pathlib import Path

import numpy as np

README = Path(__file__).parents[2] / "README.md"


def test_the_readme_cube_keeps_nine_tenths_of_its_height_on_the_ground():
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## The engine in one screen") :]
    code = re.search(r"```python\n(.*?)```", section, re.S)[1]
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)  # the README's own example
    cube, trajectory = scope["cube"], scope["trajectory"]
    height = np.ptp(trajectory.positions[:, :, 1], axis=1)
    assert height[-1] >= 0.9 * height[0]  # measured: 96 %
    assert trajectory.positions[-1, :, 1].min() >= 0.0  # on the ground, not through it
    assert np.abs(trajectory.energies.kinetic[-1]) < 0.01 * trajectory.energies.total[0]
    assert len(cube) == 1000
