"""Animations saved as GIF, HTML and (with ffmpeg) MP4."""

import base64
import html
import json
import re
import shutil
import subprocess
import zlib

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.animation import FFMpegWriter, FuncAnimation
from PIL import Image

import msdlab as msd
from msdlab import viz
from msdlab.scenes import gallery, jelly, trampoline


@pytest.fixture(scope="module")
def rope_run():
    return gallery.rope().run(steps=100, record_every=10)


def test_animate_returns_a_funcanimation_with_the_frames(rope_run):
    animation = viz.animate(rope_run, max_frames=5)
    assert isinstance(animation, FuncAnimation)
    assert len(list(animation.new_frame_seq())) == 5
    assert animation.to_jshtml().count("data:image/png;base64") == 5
    plt.close(animation._fig)  # the caller's figure: a later test starts with none


def test_gif_has_one_image_per_frame(rope_run, tmp_path):
    path = viz.save_animation(rope_run, tmp_path / "rope.gif", max_frames=6, dpi=40)
    with Image.open(path) as gif:
        assert gif.n_frames == 6


def test_html_is_a_self_contained_replay_of_positions(rope_run, tmp_path):
    path = viz.save_animation(rope_run, tmp_path / "rope.html", max_frames=4)
    page = path.read_text()
    assert '<script type="module">' in page and "data:image/png" not in page
    assert "http" not in page  # no icons or scripts from the web: it plays offline
    data = json.loads(re.search(r'id="msdlab-data">(.*?)</script>', page).group(1))
    changes = np.frombuffer(zlib.decompress(base64.b64decode(data["frames"])), np.uint16)
    levels = np.cumsum(changes.reshape(4, -1, 2), axis=0, dtype=np.uint16)  # mod 2¹⁶
    last = data["low"] + levels[-1] * np.array(data["step"])
    span = np.ptp(rope_run.positions, axis=(0, 1))
    np.testing.assert_allclose(last, rope_run.positions[-1], atol=float(span.max()) / 65535)


def test_to_html_is_inline_html_and_leaves_no_figure_open(rope_run):
    import matplotlib.pyplot as plt

    plt.close("all")
    page = viz.to_html(rope_run, max_frames=3)
    assert "<script" in page and page.count("data:image/png;base64") == 3
    assert plt.get_fignums() == []  # Jupyter shows no stray still picture


def test_the_inline_players_picture_has_the_runs_words(rope_run):
    words = viz.run_in_words(rope_run, up=1, time_unit="s")
    head, *items = words.splitlines()
    page = viz.to_html(rope_run, max_frames=3, up="y")
    assert f'<img alt="{html.escape(head)}"' in page and '<input type="range"' in page
    assert all(f"<li>{html.escape(item[2:])}</li>" in page for item in items), page[-2000:]
    assert 'aria-label="frame"' in page


def test_a_body_without_springs_animates():
    """The template's falling grid (course task 1) has particles only."""
    body = msd.Body.from_arrays([[0.0, 1.0, 0.0], [0.5, 2.0, 0.0]])
    sim = msd.Simulation(body, msd.Verlet(), 0.1, [msd.Gravity((0, -0.01, 0)), msd.Ground(0.0)])
    page = viz.to_html(sim.run(steps=50, record_every=10), max_frames=3, up="y")
    assert page.count("data:image/png;base64") == 3


def test_3d_animation_with_y_up(tmp_path):
    run = jelly.jelly_cube(size=3).run(steps=20, record_every=10)
    path = viz.save_animation(run, tmp_path / "cube.gif", max_frames=3, up="y", dpi=40)
    assert path.stat().st_size > 1000


def test_mp4_without_ffmpeg_says_what_to_do(rope_run, tmp_path, monkeypatch):
    monkeypatch.setattr(FFMpegWriter, "isAvailable", classmethod(lambda cls: False))
    with pytest.raises(RuntimeError, match=r"ffmpeg.*\.gif or \.html"):
        viz.save_animation(rope_run, tmp_path / "rope.mp4")
    assert not (tmp_path / "rope.mp4").exists()


@pytest.mark.skipif(
    shutil.which("ffprobe") is None, reason="ffmpeg is not installed (apt-get install ffmpeg)"
)
def test_mp4_with_ffmpeg_has_the_frames_at_the_pace_and_size_asked(rope_run, tmp_path):
    path = viz.save_animation(rope_run, tmp_path / "rope.mp4", max_frames=4, fps=10, dpi=40)
    streams = "stream=nb_read_frames,width,r_frame_rate"
    probe = subprocess.run(
        ["ffprobe", "-v", "error", "-count_frames", "-show_entries", streams, "-of", "json", path],
        capture_output=True,
        text=True,
        check=True,
    )
    (stream,) = json.loads(probe.stdout)["streams"]
    assert int(stream["nb_read_frames"]) == 4
    assert stream["r_frame_rate"] == "10/1"
    assert stream["width"] == 320  # 640 px at the default 80 dpi


def test_unknown_file_type_names_the_formats(rope_run, tmp_path):
    with pytest.raises(ValueError, match=r"\.gif, \.mp4, \.html"):
        viz.save_animation(rope_run, tmp_path / "rope.avi")


def test_a_net_animated_with_its_sag_shares_a_scale_between_runs():
    """Coloured by sag, the colour bar spans 15 % of the net's size (0.9 m for its 6 m)
    however deep this run sags, so a heavier ball's deeper sag shows as a deeper colour."""
    run = trampoline.trampoline(ball_mass=5.0).run(steps=100, record_every=10)
    animation = viz.animate(run, max_frames=5, colour="sag")
    figure = animation._fig
    (colour_bar,) = [ax for ax in figure.axes if ax.get_xlabel() == "sag below the rim"]
    assert colour_bar.get_xlim() == pytest.approx((0.0, 0.9))  # below the 3-D box
    assert animation.to_jshtml().count("data:image/png;base64") == 5
    plt.close(figure)
