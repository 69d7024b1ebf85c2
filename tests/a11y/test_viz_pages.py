"""The pages of the viz package meet WCAG 2.1 AA as far as axe-core can check, in headless
Chromium: the replay page `viz.save_animation` writes (``msdlab run NAME --save
NAME.html``), the inline player of `viz.to_html` (the task notebooks' animations), and the
live view as anywidget renders it (the widget page of
tests/viz/test_widget_page.py, a stand-in for the kernel behind it)."""

from __future__ import annotations

from pathlib import Path

import pytest
from accessibility import axe_violations, needs_axe
from browser import launch
from modules import module_at

import msdlab as msd
from msdlab import viz

pytestmark = [*needs_axe, pytest.mark.timeout(180)]

TESTS = Path(__file__).resolve().parents[1]


def cube_run() -> msd.Trajectory:
    """A 3 × 3 × 3 cube falling onto the ground."""
    body = msd.Body.grid((3, 3, 3), spacing=0.1, stiffness=800.0)
    body.positions += (0.0, 0.3, 0.0)
    forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground(0.0)]
    return msd.Simulation(body, msd.Verlet(0.01), dt=2e-3, forces=forces).run(
        steps=100, record_every=10
    )


def replay_page(folder: Path) -> Path:
    """The replay page of `cube_run`."""
    return viz.save_animation(cube_run(), folder / "cube.html")


def test_the_replay_page_breaks_no_wcag_rule_axe_checks(tmp_path):
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.goto(replay_page(tmp_path).as_uri())
            page.wait_for_function("() => window.msdlabViews?.[0]?.stats.drawn > 0")
            violations = axe_violations(page)
        finally:
            browser.close()
    assert not violations, "\n".join(violations)


def test_the_inline_player_breaks_no_wcag_rule_axe_checks(tmp_path):
    from playwright.sync_api import sync_playwright

    player = viz.to_html(cube_run(), max_frames=4, up="y")
    page_file = tmp_path / "player.html"
    page_file.write_text(
        '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>A player</title>'
        f"</head><body><main><h1>A falling cube</h1>{player}</main></body></html>"
    )
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page()
            page.goto(page_file.as_uri())
            page.wait_for_function("() => document.querySelector('figure img').src")
            violations = axe_violations(page)
        finally:
            browser.close()
    assert not violations, "\n".join(violations)


def test_the_live_view_breaks_no_wcag_rule_axe_checks():
    pytest.importorskip("anywidget", reason="needs anywidget (pip install -e .)")
    widget = module_at(TESTS / "viz" / "test_widget_page.py", "msdlab_widget_page")
    violations = None
    for page, _ in widget.opened(widget.spring_mass()):
        violations = axe_violations(page, context="#view")  # the widget; the page is JupyterLab's
    assert violations == [], "\n".join(violations or ["the live view did not open"])
