"""Helpers for tests in a real browser: headless Chromium, a JupyterLab server, waiting.

Tests import it (``from browser import ...``: tests/ is on every test's path); the
marks of `needs` skip them where Chromium or the Python packages are missing.
"""

import importlib.util
import json
import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Sequence
from contextlib import contextmanager
from pathlib import Path

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
# headless, offline: no first-run pages, no background requests, no updates
LAUNCH_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def needs(*packages: str) -> list[pytest.MarkDecorator]:
    """Marks skipping a test without Chromium or without ``packages``."""
    missing = [name for name in packages if not importlib.util.find_spec(name)]
    return [
        pytest.mark.skipif(
            CHROMIUM is None, reason="needs Chromium for the page (apt-get install chromium)"
        ),
        pytest.mark.skipif(
            bool(missing), reason=f"needs {', '.join(missing)} (pip install -e '.[test]')"
        ),
    ]


def launch(playwright):
    """Headless Chromium, offline, with an empty profile."""
    return playwright.chromium.launch(executable_path=CHROMIUM, args=LAUNCH_ARGS, timeout=30_000)


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def wait_until(condition, seconds: float, what: str):
    """Poll ``condition()`` until it returns something true; its value."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.1)
    raise TimeoutError(f"{what} did not happen in {seconds} s")


@contextmanager
def jupyterlab_server(
    tmp_path: Path,
    python: Path | str = sys.executable,
    root: Path | None = None,
    options: Sequence[str] = (),
):
    """A JupyterLab server of ``python`` (default: this one) on a free local port, serving
    ``root`` (default: ``tmp_path``, which holds its settings and log), with the
    command-line ``options`` added (``--ServerApp.name=value``)."""
    port, token = free_port(), "msdlab-test"
    env = {
        **os.environ,
        "JUPYTER_CONFIG_DIR": str(tmp_path / "config"),
        "JUPYTER_RUNTIME_DIR": str(tmp_path / "runtime"),
        "IPYTHONDIR": str(tmp_path / "ipython"),
        # a venv seeing the system's packages, or this one's (a journey's fresh environment
        # borrows them): their front-end extensions are there
        "JUPYTER_PATH": os.pathsep.join(
            filter(
                None,
                [
                    os.environ.get("JUPYTER_PATH"),
                    str(Path(sys.prefix, "share", "jupyter")),
                    str(Path(sys.base_prefix, "share", "jupyter")),
                ],
            )
        ),
    }
    env.pop("MPLBACKEND", None)  # the kernel picks ipympl itself
    page_config = tmp_path / "config" / "labconfig" / "page_config.json"
    page_config.parent.mkdir(parents=True, exist_ok=True)
    no_news = {"@jupyterlab/apputils-extension:announcements": True}  # no pop-up over the page
    page_config.write_text(json.dumps({"disabledExtensions": no_news}))
    log = (tmp_path / "jupyterlab.log").open("w")
    server = subprocess.Popen(
        [
            str(python),
            "-m",
            "jupyterlab",
            "--no-browser",
            "--ip=127.0.0.1",
            f"--port={port}",
            f"--IdentityProvider.token={token}",
            f"--ServerApp.root_dir={root or tmp_path}",
            "--LabApp.expose_app_in_browser=True",  # window.jupyterapp runs the cells
            "--allow-root",  # CI runs as root
            *options,
        ],
        env=env,
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    url = f"http://127.0.0.1:{port}"

    def started() -> bool:
        if server.poll() is not None:
            log.flush()
            output = (tmp_path / "jupyterlab.log").read_text()
            raise RuntimeError(f"JupyterLab stopped:\n{output}")
        return answers(f"{url}/api/status?token={token}")

    try:
        wait_until(started, 60, "JupyterLab starting")
        yield url, token
    finally:
        server.terminate()
        try:
            server.wait(timeout=15)
        except subprocess.TimeoutExpired:
            server.kill()
        log.close()


def answers(url: str) -> bool:
    try:
        with urllib.request.urlopen(url, timeout=2) as response:
            return response.status == 200
    except OSError:
        return False


def run_notebook(page, url: str, token: str, name: str) -> None:
    """Open notebook ``name`` in JupyterLab and run all its cells once the kernel is idle."""
    page.goto(f"{url}/lab/tree/{name}?token={token}")
    page.wait_for_function("window.jupyterapp && document.querySelector('.jp-Notebook')")
    page.get_by_text("Python 3 (ipykernel) | Idle").wait_for()  # the kernel is ready
    page.evaluate("() => { window.jupyterapp.commands.execute('notebook:run-all-cells'); }")
