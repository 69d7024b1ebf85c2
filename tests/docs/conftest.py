"""The documentation site, built once per test session (sphinx-build -W, as CI builds it)."""

from __future__ import annotations

import functools
import http.server
import importlib.util
import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from browser import launch

DOCS = Path(__file__).resolve().parents[2] / "docs"
MISSING = [
    name
    for name in ("sphinx", "pydata_sphinx_theme", "myst_nb", "sphinx_gallery")
    if importlib.util.find_spec(name) is None
]


@pytest.fixture(scope="session")
def site(tmp_path_factory) -> Path:
    """The built HTML site: ``sphinx-build -W --keep-going -b html docs OUT``.

    Fails with Sphinx's warnings if there are any: a broken reference, a docstring reST
    cannot read, a gallery example that raises.
    """
    if MISSING:
        pytest.skip(f"needs {', '.join(MISSING)} to build the docs (pip install -e '.[docs]')")
    out = tmp_path_factory.mktemp("docs") / "html"
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html"]
    command += ["-d", str(out.parent / "doctrees"), str(DOCS), str(out)]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    result = subprocess.run(command, capture_output=True, text=True, env=env, timeout=1200)
    assert result.returncode == 0, f"sphinx-build failed:\n{result.stdout}\n{result.stderr}"
    return out


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format, *args) -> None:
        pass


@pytest.fixture(scope="module")
def server(site):
    """The built site on http://127.0.0.1:PORT, as `python -m http.server` serves it."""
    handler = functools.partial(QuietHandler, directory=str(site))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()
    httpd.server_close()


@pytest.fixture(scope="module")
def browser():
    """Headless Chromium (`browser.launch`), one for a test file's pages (closed with it:
    a Playwright left running would meet the next file's own)."""
    pytest.importorskip("playwright", reason="needs playwright (pip install -e '.[test]')")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = launch(playwright)
        yield browser
        browser.close()
