"""The documentation site as a reader sees it: headless Chromium opens the built pages
from a local server, takes screenshots, and records every request the pages make.

The pages must load nothing from the network (no web fonts, no CDN for MathJax or the
theme), every picture must load, and the formulas must be typeset. Screenshots go to
``$MSDLAB_DOCS_SCREENSHOTS`` if set (to look at them), else into the test's folder.
"""

from __future__ import annotations

import os
from pathlib import Path
from urllib.parse import urlparse

import pytest
from browser import CHROMIUM

MATHJAX = Path("/usr/share/javascript/mathjax/MathJax.js")

pytestmark = [
    pytest.mark.skipif(
        CHROMIUM is None, reason="needs Chromium for the pages (apt-get install chromium)"
    ),
    pytest.mark.timeout(1500),
]

# One page per kind: the front page, a gallery example, a notebook, the API reference and
# a module's page in it, and a page of formulas.
PAGES = {
    "index": "index.html",
    "gallery": "gallery/scene_jelly_cube.html",
    "notebook": "notebooks/task2.html",
    "api": "api/index.html",
    "module": "api/generated/msdlab.engine.simulation.simulation.html",
    "equations": "engine/equations.html",
}


def screenshot_folder(tmp_path: Path) -> Path:
    folder = Path(os.environ.get("MSDLAB_DOCS_SCREENSHOTS") or tmp_path)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


@pytest.mark.parametrize("kind", list(PAGES))
def test_page_loads_nothing_from_the_network(kind, server, browser, tmp_path):
    host = urlparse(server).netloc
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    requested: list[str] = []
    failed: list[str] = []
    page.on("request", lambda request: requested.append(request.url))
    page.on("requestfailed", lambda request: failed.append(request.url))
    page.on("response", lambda r: r.status >= 400 and failed.append(f"{r.status} {r.url}"))
    try:
        page.goto(f"{server}/{PAGES[kind]}", wait_until="networkidle", timeout=60_000)
        if kind in ("equations", "notebook") and MATHJAX.exists():
            page.wait_for_selector(".MathJax_CHTML", timeout=30_000)  # formulas typeset
            page.wait_for_function("() => !document.querySelector('.MathJax_Processing')")
        page.screenshot(path=str(screenshot_folder(tmp_path) / f"{kind}.png"), full_page=True)
        broken = page.evaluate(
            "() => [...document.images]"
            ".filter(img => !img.complete || img.naturalWidth === 0).map(img => img.src)"
        )
        title = page.title()
    finally:
        page.close()
    outside = [
        url
        for url in requested
        if urlparse(url).scheme not in ("data", "blob", "about") and urlparse(url).netloc != host
    ]
    assert not outside, f"{kind}: requests outside the site: {outside}"
    assert not failed, f"{kind}: requests that failed: {failed}"
    assert not broken, f"{kind}: pictures that did not load: {broken}"
    assert "msdlab" in title
