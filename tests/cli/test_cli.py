"""The ``msdlab`` command line: demo, scenes, run; errors that name the valid choices."""

import io
import os
import subprocess
import sys
import time

import pytest
from matplotlib.animation import FFMpegWriter
from PIL import Image

from msdlab.cli import main
from msdlab.commands.progress import STARTING, ProgressBar
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
    for name in ("demo.gif", "demo_energy.png"):
        assert (tmp_path / name).stat().st_size > 1000
        assert str((tmp_path / name).resolve()) in out


def test_progress_bar_only_for_runs_that_take_a_moment():
    stream = io.StringIO()
    quick = ProgressBar(100, "quick", stream=stream, delay=10.0)
    quick(100)
    quick.close()
    assert stream.getvalue() == ""
    slow = ProgressBar(100, "slow", stream=stream, delay=0.0)
    slow(50)
    slow.close()
    text = stream.getvalue()
    assert "slow [###############...............]  50%" in text and "100%" in text
    assert text.endswith("\n")


def test_progress_bar_estimates_the_time_left_from_the_pace_after_the_first_step(monkeypatch):
    """A first step that loads the kernels (2 s) does not count toward the pace of the rest."""
    clock = iter([0.0, 2.0, 3.0])  # perf_counter: created, then one per call
    monkeypatch.setattr("msdlab.commands.progress.time.perf_counter", lambda: next(clock))
    stream = io.StringIO()
    bar = ProgressBar(1000, "run", stream=stream, delay=0.0)
    bar(1)  # at 2 s: one step done, the first one slow
    assert stream.getvalue().endswith("time left unknown yet")
    bar(101)  # at 3 s: 100 steps in 1 s since then, 899 to go
    assert stream.getvalue().rstrip().endswith("~ 9.0 s left")


def test_progress_bar_says_why_the_first_step_takes_long():
    """No step after ``starting_after`` s (compiling on a first run): the bar says so."""
    stream = io.StringIO()
    with ProgressBar(100, "run", stream=stream, starting_after=0.05) as bar:
        time.sleep(0.5)
        assert stream.getvalue() == f"\rrun [{'.' * 30}]   0%  {STARTING}"
        bar(1)
    lines = stream.getvalue().split("\r")
    assert lines[-1].startswith("run [##############################] 100%")
    assert lines[-1].endswith("\n") and len(lines[-1]) > len(STARTING)  # the long line blanked
    quick = ProgressBar(100, "quick", stream=stream, starting_after=0.2)
    quick(100)
    quick.close()
    quick.close()
    time.sleep(0.4)
    assert "quick" not in stream.getvalue()  # done before the delay: nothing, not even later
    assert stream.getvalue().count("\n") == 1
    idle = ProgressBar(100, "idle", stream=stream, starting_after=60.0)
    idle.close()  # no step at all, and the timer's call comes after the close
    idle._no_step_yet()
    assert "idle" not in stream.getvalue()


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
