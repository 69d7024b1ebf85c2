"""A notebook of the student release opened and saved in JupyterLab (headless Chromium): it
opens on its kernel without asking, and a save writes the metadata it shipped with, though
JupyterLab adds the kernel's Python version to it on opening."""

import json
import time
from pathlib import Path

import pytest
from browser import jupyterlab_server, launch, needs, wait_until

from msdlab.instructor import release

ROOT = Path(__file__).resolve().parents[2]

pytestmark = [*needs("jupyterlab", "playwright"), pytest.mark.timeout(240)]


def test_a_students_notebook_saved_in_jupyterlab_keeps_its_metadata(tmp_path):
    from playwright.sync_api import sync_playwright

    course = tmp_path / "course"
    release.build(course, ROOT)  # the student release, as msdlab release writes it
    path = course / "notebooks" / "task2.ipynb"
    before, written = json.loads(path.read_text())["metadata"], path.stat().st_mtime_ns
    with jupyterlab_server(tmp_path, root=course) as (url, token), sync_playwright() as play:
        browser = launch(play)
        try:
            page = browser.new_page(viewport={"width": 1200, "height": 900})
            page.goto(f"{url}/lab/tree/notebooks/task2.ipynb?token={token}")
            page.wait_for_function("window.jupyterapp && document.querySelector('.jp-Notebook')")
            page.get_by_text("Python 3 (ipykernel) | Idle").wait_for(timeout=120_000)
            time.sleep(1.0)  # the kernel's description of its language reaches the model
            page.evaluate("() => window.jupyterapp.commands.execute('docmanager:save')")
            wait_until(lambda: path.stat().st_mtime_ns != written, 60, "JupyterLab saving")
        finally:
            browser.close()
    assert json.loads(path.read_text())["metadata"] == before
