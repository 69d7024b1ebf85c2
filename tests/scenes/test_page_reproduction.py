"""`model="frame"` against the p5.js page itself: the seed's JavaScript run under node.

The page's code (springs-simple, springs-triangle, springs-fixed) is taken from
the seed document as it is and run with a small stand-in for p5's globals
(canvas size, sqrt, abs, no-op drawing, mouse never pressed). The gallery
scenes must put every particle where the page does, frame after frame.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from msdlab.scenes import gallery

SEED = Path(__file__).resolve().parents[2].parent / "shared" / "seeds" / "004_e854cccfd73dc128.txt"
FRAMES = 600

STAND_IN = """
var width = 0, height = 0, mouseX = 0, mouseY = 0, mouseIsPressed = false;
function createCanvas(w, h) { width = w; height = h; }
var sqrt = Math.sqrt, abs = Math.abs;
function background() {} function fill() {} function stroke() {} function noStroke() {}
function ellipse() {} function line() {} function text() {} function rect() {}
"""

RUN = """
setup();
%(after_setup)s
var frames = [myParticles.map(function (p) { return [p.px, p.py]; })];
for (var f = 0; f < %(frames)d; f++) {
  draw();
  frames.push(myParticles.map(function (p) { return [p.px, p.py]; }));
}
process.stdout.write(JSON.stringify(frames));
"""


def page_code(name: str) -> str:
    """The JavaScript of ``name`` (e.g. "springs-simple.js") as printed in the seed."""
    text = SEED.read_text(encoding="utf-8")
    start = text.index(f"\n{name}\n") + len(name) + 2
    end = text.index("\n}\n", text.index("var Spring = function Spring()", start)) + 3
    return text[start:end]


def run_page(name: str, after_setup: str = "") -> np.ndarray:
    """Particle positions (frames + 1, N, 2) on the page, in page pixels (y down)."""
    script = STAND_IN + page_code(name) + RUN % {"after_setup": after_setup, "frames": FRAMES}
    done = subprocess.run(
        ["node", "-"], input=script, capture_output=True, text=True, timeout=60, check=True
    )
    return np.array(json.loads(done.stdout))


needs_the_page = pytest.mark.skipif(
    shutil.which("node") is None or not SEED.exists(),
    reason="needs node (apt-get install nodejs) and the seed document ../shared/seeds/004_*.txt",
)


@needs_the_page
@pytest.mark.parametrize(
    ("page", "after_setup", "scene"),
    [
        # The page invites the reader to pull a particle; the scene starts pulled 50 px.
        ("springs-simple.js", "myParticles[1].px += 50;", gallery.two_particles),
        ("springs-triangle.js", "", gallery.triangle),
        ("springs-fixed.js", "", gallery.hanging_particle),
    ],
)
def test_the_frame_model_puts_every_particle_where_the_page_does(page, after_setup, scene):
    on_page = run_page(page, after_setup)
    trajectory = scene(model="frame").run(steps=FRAMES)
    ours = trajectory.positions.copy()
    ours[..., 1] = gallery.HEIGHT - ours[..., 1]  # y up here, down on the page
    assert ours.shape == on_page.shape
    assert np.max(np.abs(ours - on_page)) <= 1e-9
    assert np.ptp(on_page[:, :, 1]) > 10.0 or np.ptp(on_page[:, :, 0]) > 10.0  # it moved


@needs_the_page
def test_the_triangle_bounces_past_the_floor_as_on_the_page():
    """The page's hard walls never move a particle back: it sinks below the floor."""
    on_page = run_page("springs-triangle.js")
    assert on_page[:, :, 1].max() > gallery.HEIGHT + 1.0
