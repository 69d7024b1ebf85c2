"""Every page of the documentation site meets WCAG 2.1 AA as far as axe-core can check, in
headless Chromium; the gallery's pictures say in words what they show, and its animations
play only when a reader asks.

axe-core's rules on colours (contrast of text, links told from text) take most of its
time, and a page's colours are its theme's and its kind's (the same on every page of a
kind): they run on one page of each kind, `COLOURS`; every other rule on every page.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser
from pathlib import Path

import pytest
from accessibility import axe_violations, needs_axe

pytestmark = [*needs_axe, pytest.mark.timeout(1500)]

COLOURS = {
    "index.html",  # the front page: its picture, the table of extras
    "accessibility.html",
    "student/live-view.html",  # pictures, tables
    "instructor/grading.html",
    "engine/equations.html",  # formulas
    "engine/architecture.html",  # a drawn picture
    "gallery/index.html",  # thumbnails
    "gallery/scene_jelly_cube.html",  # a gallery example: code, output, picture, animation
    "notebooks/task2.html",  # a notebook: cells and their outputs
    "api/index.html",
    "api/generated/msdlab.engine.simulation.simulation.html",  # a module's reference
}


TYPESET = "() => window.MathJax?.Hub && new Promise((done) => MathJax.Hub.Queue(done))"
"""Waits for MathJax, where a page has it, to have typeset its formulas."""


def pages(site: Path) -> list[str]:
    """Every HTML page of the site, as a path under it (not the files beside the pages in
    _static, _images, ...)."""
    found = (p.relative_to(site).as_posix() for p in sorted(site.rglob("*.html")))
    return [p for p in found if not p.startswith("_")]


def test_every_page_breaks_no_wcag_rule_axe_checks(site, server, browser):
    assert set(pages(site)) >= COLOURS, sorted(COLOURS - set(pages(site)))
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    broken = {}
    try:
        for path in pages(site):
            page.goto(f"{server}/{path}", wait_until="load", timeout=60_000)
            page.evaluate(TYPESET)
            violations = axe_violations(page, colours=path in COLOURS)
            if violations:
                broken[path] = violations
    finally:
        page.close()
    assert not broken, "\n".join(f"{path}:\n  " + "\n  ".join(v) for path, v in broken.items())


class Pictures(HTMLParser):
    """The pictures of a page: (src, alt, inside a closed <details>)."""

    def __init__(self) -> None:
        super().__init__()
        self.found: list[tuple[str, str, bool]] = []
        self.open_details: list[bool] = []  # each enclosing <details>: open or not

    def handle_starttag(self, tag: str, attrs: list) -> None:
        attributes = dict(attrs)
        if tag == "details":
            self.open_details.append("open" in attributes)
        elif tag == "img":
            folded = any(not is_open for is_open in self.open_details)
            self.found.append((attributes.get("src", ""), attributes.get("alt") or "", folded))

    def handle_endtag(self, tag: str) -> None:
        if tag == "details" and self.open_details:
            self.open_details.pop()


def pictures(page: Path) -> list[tuple[str, str, bool]]:
    parser = Pictures()
    parser.feed(page.read_text(encoding="utf-8"))
    return parser.found


def test_every_animation_is_folded_until_the_reader_plays_it(site):
    """A GIF plays by itself, longer than 5 s: it must be one a reader can stop (WCAG
    2.2.2): closed in a <details> until opened, stopped by closing it."""
    animations = [
        (path, src, folded)
        for path in pages(site)
        for src, _, folded in pictures(site / path)
        if src.endswith(".gif")
    ]
    assert len(animations) >= 10  # the gallery's examples
    playing = [f"{path}: {src}" for path, src, folded in animations if not folded]
    assert not playing, f"animations playing by themselves: {playing}"


def test_the_gallery_pictures_say_what_they_show(site):
    """A gallery example's still says the scene, its particles and springs and the strains
    its lines and colours stand for; its animation what the run is."""
    examples = sorted((site / "gallery").glob("scene_*.html"))
    assert examples
    for example in examples:
        shown = [(src, alt) for src, alt, _ in pictures(example) if "sphx_glr_" in src]
        assert shown, example.name
        for src, alt in shown:
            if src.endswith(".gif"):
                assert alt.startswith("Animation of the run of"), (example.name, alt)
            else:
                described = re.search(r"\d+ particles?, \d+ springs? (drawn|coloured) by", alt)
                assert described, (example.name, alt)
