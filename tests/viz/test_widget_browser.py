"""The live widget in JupyterLab, in headless Chromium, driven as a person would: it draws,
a dragged particle follows the mouse, the stiffness slider changes the engine's springs, and
the energy bars add up to the ledger's total.

The notebook made for the test runs `viz.show` on the gallery's mesh and starts a thread
that writes, ten times a second, what the engine has to ``state.json`` beside it.
"""

import json
import time
from pathlib import Path

import nbformat
import numpy as np
import pytest
from browser import jupyterlab_server, launch, needs, run_notebook, wait_until

pytestmark = [*needs("jupyterlab", "anywidget", "playwright"), pytest.mark.timeout(240)]

KERNEL = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
SHOW = """\
from msdlab import viz
from msdlab.scenes import SCENES

live = viz.show(SCENES["mesh"].build(), steps_per_second=60)
"""

REPORTER = """\
import json
import threading
import time
from pathlib import Path

import numpy as np

def report() -> None:
    \"\"\"What the engine has: positions, the held particle, stiffness and, when paused,
    the ledger's total of the energy in the body.\"\"\"
    while True:
        sim = live.sim
        state = {
            "held": live.grab.particle,
            "positions": sim.body.positions.tolist(),
            "stiffness": float(np.mean(sim.body.stiffness)),
            "running": live.running,
            "steps": sim.step_count,
        }
        if not live.running:
            time.sleep(0.2)  # the last frame sent
            state["ledger_total"] = float(sim.run(steps=0).energies.total[0])
            state["energy"] = live.energy
        Path("state.json.part").write_text(json.dumps(state))
        Path("state.json.part").replace("state.json")
        time.sleep(0.1)

threading.Thread(target=report, daemon=True).start()
"""


def read_state(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (FileNotFoundError, json.JSONDecodeError):
        return None


@pytest.fixture
def page_with_widget(tmp_path):
    """A JupyterLab page running the widget notebook; (page, state reader)."""
    from playwright.sync_api import sync_playwright

    notebook = nbformat.v4.new_notebook(metadata={"kernelspec": KERNEL})
    notebook.cells = [nbformat.v4.new_code_cell(s) for s in (SHOW, REPORTER)]
    nbformat.write(notebook, tmp_path / "live.ipynb")
    with jupyterlab_server(tmp_path) as (url, token), sync_playwright() as playwright:
        browser = launch(playwright)
        page = browser.new_page(viewport={"width": 1400, "height": 1200})
        page.set_default_timeout(60_000)
        try:
            run_notebook(page, url, token, "live.ipynb")
            page.locator(".msdlab-canvas").wait_for(state="visible")
            page.locator(".msdlab-canvas").scroll_into_view_if_needed()
            yield page, lambda: read_state(tmp_path / "state.json")
        except Exception:
            page.screenshot(path=tmp_path / "page.png")
            raise
        finally:
            browser.close()


def screen_of(page) -> np.ndarray:
    """Page coordinates (px) of the particles as the widget last drew them."""
    box = page.locator(".msdlab-canvas").bounding_box()
    screen = page.evaluate("() => Array.from(window.msdlabViews.at(-1).painter.screen)")
    return np.array(screen).reshape(-1, 2) + (box["x"] + 1, box["y"] + 1)  # 1 px border


def engine_screen(page, position: list[float]) -> np.ndarray:
    """Page coordinates (px) of the engine's ``position`` through the widget's camera."""
    box = page.locator(".msdlab-canvas").bounding_box()
    screen = page.evaluate(
        """(x) => { const out = new Float32Array(2), depth = new Float32Array(1);
        window.msdlabViews.at(-1).camera.project(Float32Array.from(x), 1, out, depth);
        return Array.from(out); }""",
        position,
    )
    return np.array(screen) + (box["x"] + 1, box["y"] + 1)


def test_the_widget_draws_drags_sets_and_adds_up(page_with_widget):
    page, state = page_with_widget
    # it draws: frames counted by requestAnimationFrame, with positions from the engine
    wait_until(
        lambda: page.evaluate("() => window.msdlabViews.at(-1).stats.drawn > 30"),
        30,
        "the widget drawing",
    )
    wait_until(lambda: (s := state()) and s["steps"] > 120, 30, "the mesh settling")

    # a scripted drag: press on the top-right corner, move left and up, hold still
    screen = screen_of(page)
    particle = int(np.argmax(screen[:, 0] - screen[:, 1]))
    press = screen[particle]
    release = press + (-120.0, -60.0)
    page.mouse.move(*press)
    page.mouse.down()
    for fraction in np.linspace(0.1, 1.0, 10):
        page.mouse.move(*(press + fraction * (release - press)))
        time.sleep(0.05)

    def arrived():  # in the engine, not only on the page (which draws it at the hand)
        s = state()
        if not s or s["held"] != particle:
            return None
        return np.abs(engine_screen(page, s["positions"][particle]) - release).max() <= 2.0

    wait_until(arrived, 20, "the held particle reaching the mouse")
    page.mouse.up()
    wait_until(lambda: state()["held"] is None, 10, "letting go")

    # the stiffness slider sets the stiffness the engine uses
    slider = page.locator('input[data-setting="stiffness"]')
    chosen = slider.evaluate(
        "(s) => { s.value = 0.2; s.dispatchEvent(new Event('change')); return Number(s.value); }"
    )  # 0.2 on the slider's steps
    assert chosen == pytest.approx(0.2, abs=0.002)
    wait_until(lambda: abs(state()["stiffness"] - chosen) < 1e-9, 10, "the new stiffness")

    # paused, the bars of the energy in the body add up to the ledger's total
    page.get_by_text("❚❚ pause").click()
    paused = wait_until(lambda: (s := state()) and "ledger_total" in s and s, 10, "pausing")
    time.sleep(0.5)
    bars = json.loads(page.locator(".msdlab-energy").get_attribute("data-bars"))
    in_body = bars["kinetic"] + bars["elastic"] + bars["gravitational"]
    in_body += bars.get("other potential", 0.0) + paused["energy"]["zero"]  # from the floor
    assert in_body == pytest.approx(paused["ledger_total"], rel=1e-9, abs=1e-9)
    total = float(page.locator(".msdlab-energy").get_attribute("data-total"))
    assert total == pytest.approx(sum(bars.values()), rel=1e-12)
