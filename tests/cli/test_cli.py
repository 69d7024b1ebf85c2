"""The ``msdlab`` command line: demo, scenes, run; errors that name the valid choices."""

import io
import os
import re
import subprocess
import sys
import time

import pytest
from matplotlib.animation import FFMpegWriter
from matplotlib.text import Text
from PIL import Image

from msdlab.cli import main
from msdlab.commands.progress import STARTING, step_bar
from msdlab.scenes import SCENES


def test_scenes_lists_one_line_per_scene(capsys):
    assert main(["scenes"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == len(SCENES)
    assert [line.split()[0] for line in lines] == list(SCENES)


def test_scenes_name_shows_its_settings(capsys):
    assert main(["scenes", "trampoline"]) == 0
    out = capsys.readouterr().out
    assert "ball_mass = 1.0" in out and "stiffness = 999.0" in out


def test_run_prints_the_energy_ledger(capsys):
    assert main(["run", "two-particles", "--duration", "30"]) == 0
    out = capsys.readouterr().out
    assert "kinetic" in out and "drift" in out


def test_run_with_settings_integrator_dt_and_gif(tmp_path, capsys):
    path = tmp_path / "rope.gif"
    args = ["run", "hanging-rope", "--set", "model=frame", "--set", "count=10"]
    args += ["--duration", "40", "--dt", "0.5", "--save", str(path)]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "FrameEuler" in out and "dt=0.5" in out and str(path.resolve()) in out
    with Image.open(path) as gif:
        assert gif.n_frames > 10
    assert main(["run", "mesh", "--integrator", "rk4", "--duration", "5"]) == 0
    assert "RK4()" in capsys.readouterr().out


def test_run_saves_html(tmp_path):
    path = tmp_path / "cube.html"
    args = ["run", "jelly-cube", "--set", "size=3", "--duration", "20", "--save", str(path)]
    assert main(args) == 0
    assert "<script" in path.read_text()


def test_blow_up_is_explained_not_a_traceback(capsys):
    assert main(["run", "cloth", "--integrator", "explicit-euler", "--duration", "2"]) == 1
    out = capsys.readouterr().out
    assert "blew up" in out and "stable limit" in out


def test_trampoline_experiments_table(capsys):
    assert main(["run", "trampoline", "--experiments", "--duration", "0.5"]) == 0
    out = capsys.readouterr().out
    for name in ("control", "heavier", "off-centre", "off-centre-big", "net-11x11", "k-450"):
        assert name in out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["run", "cloth", "--set", "colour=red"], "valid settings: nodes, extent"),
        (["run", "cloth", "--set", "pin"], "key=value"),
        (["run", "cloth", "--set", "pin=left"], "corners, row"),
        (["run", "blob", "--save", "blob.avi"], ".gif, .mp4, .html"),
        (["run", "blob", "--experiments"], "trampoline --experiments"),
        (["run", "blob", "--show"], "no display"),
        (["scenes", "sofa"], "choose one of: jelly-cube, trampoline"),
    ],
)
def test_errors_name_the_valid_choices(args, message, capsys):
    assert main(args) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["run", "sofa"], "choose from 'jelly-cube', 'trampoline'"),
        (["run", "blob", "--integrator", "leapfrog"], "choose from 'explicit-euler'"),
    ],
)
def test_argument_errors_name_the_valid_choices(args, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(args)
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err


def test_mp4_without_ffmpeg_fails_before_running(monkeypatch, capsys):
    monkeypatch.setattr(FFMpegWriter, "isAvailable", classmethod(lambda cls: False))
    assert main(["run", "trampoline", "--save", "ball.mp4"]) == 2
    captured = capsys.readouterr()
    assert "ffmpeg" in captured.err and "kinetic" not in captured.out


@pytest.mark.parametrize("command", [[], ["demo"], ["scenes"], ["run"]])
def test_help_everywhere(command, capsys):
    with pytest.raises(SystemExit) as exit_:
        main([*command, "--help"])
    assert exit_.value.code == 0
    assert "usage: msdlab" in capsys.readouterr().out


def test_demo_writes_animation_and_plot(tmp_path, capsys):
    args = ["demo", "--out", str(tmp_path), "--size", "3", "--steps", "100", "--frames", "3"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "kinetic" in out
    assert re.search(r"dt = 0.4 template units \(the engine predicts this integrator stable "
                     r"below dt = [\d.]+ template units\)", out)  # fmt: skip
    header = next(line for line in out.splitlines() if line.split()[:2] == ["time", "kinetic"])
    legend = out[out.index("time in template units, energies in template units") :]
    for column in header.split():  # every column of the ledger is explained below it
        assert re.search(rf"^  {column} +\S", legend, re.M), column
    assert "taken out so far by the integrator's damping λ" in legend
    for name in ("demo.gif", "demo_energy.png"):
        assert (tmp_path / name).stat().st_size > 1000
        assert str((tmp_path / name).resolve()) in out


def test_demo_names_the_template_units_not_seconds_and_joules(tmp_path, capsys, monkeypatch):
    """The demo runs the brief's setting (dt = 0.4, g = -0.001 in the template's units): its
    animation's clock and energy plot must not claim seconds or joules."""
    shown: list[str] = []
    set_text = Text.set_text
    monkeypatch.setattr(Text, "set_text", lambda self, s: (shown.append(str(s)), set_text(self, s)))
    args = ["demo", "--out", str(tmp_path), "--size", "3", "--steps", "10", "--frames", "2"]
    assert main(args) == 0
    assert "time (template units)" in shown and "energy (template units)" in shown
    titles = [text for text in shown if text.startswith("jelly cube")]
    assert titles and all(re.search(r"t = [\d.]+ template units", t) for t in titles)
    assert not [t for t in shown if re.search(r"\(s\)|\(J\)| J$|t = [\d.]+ s\b", t)]


def test_progress_bar_only_for_runs_that_take_a_moment():
    stream = io.StringIO()
    with step_bar(100, "quick", file=stream, delay=10.0) as bar:
        bar(100)
    assert stream.getvalue() == ""
    with step_bar(100, "slow", file=stream, delay=0.0) as bar:
        bar(50)
    text = stream.getvalue()
    assert "slow:  50%|#####     | 50/100" in text and text.endswith("\n")


def test_progress_bar_says_why_the_first_step_takes_long():
    """No step after ``note_after`` s (compiling on a first run): a line says so, once."""
    stream = io.StringIO()
    with step_bar(100, "run", file=stream, note_after=0.05) as bar:
        time.sleep(0.5)
        assert stream.getvalue().count(STARTING + "\n") == 1
        bar(1)
    quick = io.StringIO()
    with step_bar(100, "quick", file=quick, note_after=0.2) as bar:
        bar(100)
    time.sleep(0.4)
    assert quick.getvalue() == ""  # done before the delay: nothing, not even later


def test_quick_start_demo_in_a_real_process(tmp_path):
    """The README's `msdlab demo`, as a user runs it: a few seconds, no display."""
    result = subprocess.run(
        [sys.executable, "-m", "msdlab", "demo", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    assert result.returncode == 0, result.stderr
    assert "animation:" in result.stdout and (tmp_path / "demo.gif").exists()
