"""The live view driven as a person would: a real Tk window under Xvfb, the mouse moved by
xdotool (press on a particle, move, release); the grabbed particle follows the mouse."""

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

TOOLS = [tool for tool in ("Xvfb", "xdotool") if shutil.which(tool) is None]


def has_tk() -> bool:
    try:
        import tkinter  # noqa: F401
    except ImportError:
        return False
    return True


pytestmark = [
    pytest.mark.skipif(
        bool(TOOLS), reason=f"needs {' and '.join(TOOLS)} (apt-get install xvfb xdotool)"
    ),
    pytest.mark.skipif(
        not has_tk(), reason="this Python has no tkinter (apt-get install python3-tk)"
    ),
]


def wait_for(path: Path, seconds: float) -> None:
    deadline = time.monotonic() + seconds
    while not path.exists():
        if time.monotonic() > deadline:
            raise TimeoutError(f"{path.name} did not appear in {seconds} s")
        time.sleep(0.1)


@pytest.fixture
def display(tmp_path):
    """A virtual X display of its own (-displayfd picks a free number)."""
    read, write = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
        pass_fds=[write],
        stderr=subprocess.DEVNULL,
    )
    os.close(write)
    with os.fdopen(read) as pipe:
        number = pipe.readline().strip()
    yield f":{number}"
    server.terminate()
    server.wait(timeout=10)


def test_a_dragged_particle_follows_the_mouse_in_a_tk_window(display, tmp_path):
    env = {**os.environ, "DISPLAY": display}
    window = subprocess.Popen(
        [sys.executable, str(Path(__file__).with_name("live_window.py")), str(tmp_path)], env=env
    )
    try:
        wait_for(tmp_path / "aim.json", 60)
        aim = json.loads((tmp_path / "aim.json").read_text())

        def xdotool(*args) -> None:
            subprocess.run(["xdotool", *map(str, args)], env=env, check=True, timeout=10)

        xdotool("mousemove", *np.round(aim["press"]).astype(int))
        xdotool("mousedown", 1)
        for fraction in np.linspace(0.1, 1.0, 10):  # a hand moves in small steps
            point = np.add(aim["press"], fraction * np.subtract(aim["release"], aim["press"]))
            xdotool("mousemove", *np.round(point).astype(int))
            time.sleep(0.05)
        time.sleep(0.5)  # held still: the particle sits under the mouse
        (tmp_path / "done").touch()
        wait_for(tmp_path / "result.json", 30)
        xdotool("mouseup", 1)
        result = json.loads((tmp_path / "result.json").read_text())
    finally:
        window.wait(timeout=30)
    assert result["held"] == 37  # the particle under the mouse was taken
    assert np.linalg.norm(np.subtract(result["position"], aim["start"])) > 60.0  # it came along
    np.testing.assert_allclose(result["on_screen"], aim["release"], atol=2.0)  # under the mouse
