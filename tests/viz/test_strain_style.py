"""Strain reads without colour and with any colour vision: the map's ends stay apart under
simulated colour blindness, every colour keeps 3:1 against white, and the lines carry the
strain's sign in the pictures, the live view and the replay page alike."""

import json
import re

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import Normalize, to_hex, to_rgb

import msdlab as msd
from msdlab import viz
from msdlab.scenes import gallery
from msdlab.viz.frontend import describe
from msdlab.viz.lines import LEVELS, SpringLines
from msdlab.viz.replay import replay_page
from msdlab.viz.strain_style import KEY, STRAIN_MAP, STROKES, stroke_classes

# Machado, Oliveira and Fernandes (2009), severity 1: linear RGB seen as a dichromat sees it
DICHROMACIES = {
    "protanopia": [
        [0.152286, 1.052583, -0.204868],
        [0.114503, 0.786281, 0.099216],
        [-0.003882, -0.048116, 1.051998],
    ],
    "deuteranopia": [
        [0.367322, 0.860646, -0.227968],
        [0.280085, 0.672501, 0.047413],
        [-0.011820, 0.042940, 0.968881],
    ],
    "tritanopia": [
        [1.255528, -0.076749, -0.178779],
        [-0.078411, 0.930809, 0.147602],
        [0.004733, 0.691367, 0.303900],
    ],
    "typical": np.eye(3).tolist(),
}
SRGB_TO_XYZ = np.array(
    [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]
)
WHITE = np.array([0.95047, 1.0, 1.08883])


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def linear(rgb: np.ndarray) -> np.ndarray:
    """sRGB (0 to 1) to linear RGB."""
    rgb = np.asarray(rgb, dtype=float)
    return np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)


def lab(linear_rgb: np.ndarray) -> np.ndarray:
    """CIELAB (L*, a*, b*) of linear RGB colours (..., 3), white D65."""
    xyz = linear_rgb @ SRGB_TO_XYZ.T / WHITE
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16 / 116)
    return np.stack(
        [116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])], -1
    )


def levels() -> list[str]:
    """The map's colours at the middles of its `LEVELS` levels, as the springs are drawn."""
    return [to_hex(STRAIN_MAP((level + 0.5) / LEVELS)) for level in range(LEVELS)]


def seen(colours: list[str], dichromacy: str) -> np.ndarray:
    """CIELAB of ``colours`` as seen with ``dichromacy``."""
    matrix = np.array(DICHROMACIES[dichromacy])
    return lab(np.clip(linear([to_rgb(c) for c in colours]) @ matrix.T, 0.0, 1.0))


@pytest.mark.parametrize("dichromacy", DICHROMACIES)
def test_the_maps_ends_and_middle_stay_apart_with_colour_blindness(dichromacy):
    table = levels()
    squeezed, rest, stretched = seen([table[0], table[LEVELS // 2], table[-1]], dichromacy)
    assert np.linalg.norm(squeezed - stretched) > 60  # ΔE*ab: 2.3 is just noticeable
    assert np.linalg.norm(squeezed - rest) > 20 and np.linalg.norm(stretched - rest) > 20
    lightness = seen(table, dichromacy)[:, 0]
    middle, rounding = LEVELS // 2, 0.2  # L* a step of the hex colours' 1/255 can move
    assert np.all(np.diff(lightness[middle:]) < rounding)  # darker the more it is stretched
    assert np.all(np.diff(lightness[:middle]) > -rounding)  # and the more it is squeezed
    assert min(lightness[middle] - lightness[0], lightness[middle] - lightness[-1]) > 8


def test_every_colour_of_the_map_has_3_to_1_contrast_against_white():
    luminance = linear([to_rgb(c) for c in levels()]) @ [0.2126, 0.7152, 0.0722]
    assert np.min(1.05 / (luminance + 0.05)) >= 3.0  # WCAG 1.4.11, non-text contrast


def test_the_levels_fall_in_three_classes_symmetric_about_rest():
    classes = stroke_classes(np.arange(LEVELS), LEVELS)
    assert classes.tolist() == [0] * 24 + [1] * 16 + [2] * 24
    squeezed, rest, stretched = STROKES
    assert squeezed.width < rest.width < stretched.width and squeezed.dash and not rest.dash


def test_matplotlib_springs_are_thick_stretched_and_thin_dashed_squeezed():
    ends = np.zeros((3, 2, 2))
    springs = SpringLines(
        ends, [-0.9, 0.0, 0.9], stroke_width=1.0, cmap=STRAIN_MAP, norm=Normalize(-1, 1)
    )
    assert list(springs.get_linewidths()) == [0.75, 1.0, 2.0]
    dashes = [pattern for _, pattern in springs.get_linestyles()]
    assert dashes[0] is not None and dashes[1] is None and dashes[2] is None


def test_a_picture_of_a_pulled_body_has_its_key(tmp_path):
    figure = viz.plot_body(gallery.two_particles(pull=50.0).body, save=tmp_path / "body.png")
    springs = figure.axes[0].collections[0]
    assert list(springs.get_linewidths()) == [2.4]  # stretched by 0.5: thick
    (key,) = figure.legends
    assert [text.get_text() for text in key.get_texts()] == [
        "stretched",
        "near rest length",
        "squeezed",
    ]


def test_the_live_view_and_replay_page_get_each_levels_line_and_the_key():
    sim = gallery.mesh()
    scene = describe(sim, up="y", view=None, strain_limit=0.3)
    assert [s["name"] for s in scene["strokes"]] == [s.name for s in STROKES]
    assert scene["strokes"][0]["dash"] and scene["strokes"][2]["dash"] == []
    assert scene["stroke_of_level"] == stroke_classes(np.arange(LEVELS), LEVELS).tolist()
    assert scene["key"] == KEY and scene["colours"] == levels()  # the pictures' colours
    run = msd.Simulation(sim.body).run(steps=2, record_every=1)
    page = replay_page(run, np.arange(2), fps=10, up="y", view=None, strain_limit=0.3)
    data = json.loads(re.search(r'id="msdlab-data">(.*?)</script>', page, re.S)[1])
    assert data["scene"]["strokes"] == scene["strokes"]
    assert "strainKey(root, scene)" in page  # live.js draws the key under the body
