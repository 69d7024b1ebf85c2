"""The site's picture of a jelly cube is drawn by docs/pictures.py, as its docstring says."""

from __future__ import annotations

from modules import module_at
from PIL import Image

from msdlab.course import PROJECT_ROOT


def test_the_jelly_picture_is_drawn_squashed_with_its_words(tmp_path):
    import matplotlib.pyplot as plt

    pictures = module_at(PROJECT_ROOT / "docs" / "pictures.py", "msdlab_docs_pictures")
    words = pictures.main(tmp_path / "jelly.png")
    assert plt.get_fignums() == []  # closed: the next test in this process starts with none
    assert Image.open(tmp_path / "jelly.png").size == Image.open(pictures.PICTURE).size
    assert words.startswith("The squashed jelly cube: a body of 216 particles and 1440 springs")
    assert "its lowest point at y = 0;" in words
    low, high = (float(p) for p in words.split("strain from ")[1].rstrip("%").split("% to "))
    assert low < -10 < 5 < high  # squeezed upright, stretched level
