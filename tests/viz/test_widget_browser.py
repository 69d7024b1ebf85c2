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
            "stiffness": float(np.mean(sim.body.edges().stiffness)),
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
    # the total: in the body, plus what was taken out, less the hand's work (put in)
    work = bars.pop("hand's work")
    assert work > 0.0  # the hand dragged a particle above
    assert total == pytest.approx(sum(bars.values()) - work, rel=1e-12)


COUNTS = """() => { const s = window.msdlabViews.at(-1).stats;
return [s.received, s.updates, s.pictures, performance.now()]; }"""
BOOKS = """() => { const c = document.querySelector('.msdlab-energy');
return [Number(c.dataset.total), JSON.parse(c.dataset.bars)["hand's work"] ?? 0]; }"""


def test_every_state_is_shown_and_a_hands_circle_is_booked(page_with_widget):
    page, state = page_with_widget
    wait_until(lambda: (s := state()) and s["steps"] > 120, 60, "the mesh settling")
    screen = screen_of(page)
    particle = screen[int(np.argmax(screen[:, 0] - screen[:, 1]))]
    books = page.evaluate(BOOKS)
    counts = page.evaluate(COUNTS)
    page.mouse.move(*particle)
    page.mouse.down()
    start = time.perf_counter()
    while (elapsed := time.perf_counter() - start) < 4.0:  # once round a circle of 30 px
        angle = 2 * np.pi * elapsed / 4.0
        page.mouse.move(*(particle + 30.0 * np.array([np.cos(angle) - 1.0, np.sin(angle)])))
        time.sleep(1 / 60)
    received, shown, pictures, now = np.array(page.evaluate(COUNTS)) - counts
    page.mouse.up()
    time.sleep(1.5)  # the energies of a state after the release
    total, work = np.array(page.evaluate(BOOKS)) - books
    # each state that came is shown, in a frame of its own, as a picture of its own
    assert shown >= 0.7 * received and pictures >= 0.7 * received  # before: 0.6
    # a floor that holds on a loaded 2-core machine (12 a second seen with 14 processes
    # waiting for its cores; 55 or more on a quiet one)
    assert 1000 * pictures / now >= 8.0, f"{1000 * pictures / now:.1f} new pictures a second"
    # the energy panel's total (in the body and taken out) moves by the hand's work only
    assert work > 50.0  # the hand put energy in: its bar (px²/frame², unit masses)
    # the kernel plays the hand's moves back at the pace the hand made them, however they
    # arrive: within 1 % on a quiet machine; the bound leaves room for CI's load
    drift = f"the total moved {total:.4g} for the hand's work {work:.4g}"
    print(drift)
    assert abs(total) <= 0.03 * work, drift  # before: 3.5 to 8 %, the moves in bursts
