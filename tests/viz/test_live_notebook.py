"""The matplotlib live view (`Dragger`) driven as a person would in Jupyter: JupyterLab with
ipympl in headless Chromium runs a cell dragging the gallery's mesh, the mouse presses on a
particle, drags it and holds still; the particle follows the mouse. (`viz.show` in a
notebook is the widget, tested in test_widget_browser.py.)

The notebook made for the test holds the mesh's dragging cell and a cell that writes, ten
times a second, where the particles are on the figure (pixels) and which one is held to
``state.json`` beside it.
"""

import itertools
import json
import time
from pathlib import Path

import nbformat
import numpy as np
import pytest
from browser import CHROMIUM, jupyterlab_server, needs, wait_until

GALLERY = Path(__file__).resolve().parents[2] / "notebooks" / "scene_gallery.ipynb"

pytestmark = [*needs("jupyterlab", "ipympl", "playwright"), pytest.mark.timeout(120)]

REPORTER = """\
import json
import time
from pathlib import Path

def report_state() -> None:
    \"\"\"Where the particles are on the figure (px, y up), which one is held, and when.\"\"\"
    figure = dragger.ax.figure
    state = {
        "written": time.time(),
        "held": dragger.grab.particle,
        "pixels": dragger.ax.transData.transform(dragger.sim.body.positions).tolist(),
        "figure": [figure.bbox.width, figure.bbox.height],
    }
    Path("state.json.part").write_text(json.dumps(state))
    Path("state.json.part").replace("state.json")

reporter = dragger.ax.figure.canvas.new_timer(interval=100)
reporter.add_callback(report_state)
reporter.start()
"""


DRAGGING = """\
%matplotlib widget
from msdlab import viz
from msdlab.scenes import gallery

# ipympl shows the figure as it is made
dragger = viz.Dragger(gallery.mesh(), steps_per_second=60).start()  # the page's pace
"""


def drag_notebook(folder: Path) -> Path:
    """The dragging cell and the reporter, as ``folder/drag.ipynb``."""
    gallery = nbformat.read(GALLERY, as_version=4)
    notebook = nbformat.v4.new_notebook(metadata=gallery.metadata)
    notebook.cells = [nbformat.v4.new_code_cell(s) for s in (DRAGGING, REPORTER)]
    path = folder / "drag.ipynb"
    nbformat.write(notebook, path)
    return path


@pytest.fixture
def jupyterlab(tmp_path):
    with jupyterlab_server(tmp_path) as server:
        yield server


def read_state(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (FileNotFoundError, json.JSONDecodeError):
        return None


def test_a_dragged_particle_follows_the_mouse_in_jupyterlab(jupyterlab, tmp_path):
    from playwright.sync_api import sync_playwright

    url, token = jupyterlab
    drag_notebook(tmp_path)
    state_file = tmp_path / "state.json"
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=CHROMIUM, args=["--no-sandbox", "--disable-gpu"], timeout=30_000
        )
        try:
            page = browser.new_page(viewport={"width": 1400, "height": 1200})
            page.set_default_timeout(40_000)
            page.goto(f"{url}/lab/tree/drag.ipynb?token={token}")
            page.wait_for_function("window.jupyterapp && document.querySelector('.jp-Notebook')")
            page.get_by_text("Python 3 (ipykernel) | Idle").wait_for()  # the kernel is ready
            page.evaluate("() => { window.jupyterapp.commands.execute('notebook:run-all-cells'); }")
            canvas = page.locator(".jupyter-matplotlib-canvas-div canvas").last
            canvas.wait_for(state="visible")
            canvas.scroll_into_view_if_needed()
            # the mesh falls onto the floor and settles: aim once it is still
            last: list[np.ndarray] = []

            def settled():
                state = read_state(state_file)
                if state is None:
                    return None
                last.append(np.array(state["pixels"]))
                if len(last) > 5 and np.abs(last[-1] - last[-6]).max() < 0.5:
                    return state
                return None

            state = wait_until(settled, 40, "the mesh settling in the live view")
            width, height = state["figure"]

            def on_page(pixel) -> np.ndarray:
                """Page coordinates (y down) of a figure pixel (y up), where the canvas is now
                (the notebook's layout may still move it, e.g. when an output appears)."""
                box = canvas.bounding_box()
                scale = np.array([box["width"] / width, box["height"] / height])
                return np.array([box["x"], box["y"] + box["height"]]) + scale * (1, -1) * pixel

            pixels = np.array(state["pixels"])
            particle = int(np.argmax(pixels.sum(axis=1)))  # the top-right corner
            press = on_page(pixels[particle])
            release = press + (-120.0, -60.0)  # to the left and up on the page
            page.mouse.move(*press)
            page.mouse.down()
            for fraction in np.linspace(0.1, 1.0, 10):  # a hand moves in small steps
                page.mouse.move(*(press + fraction * (release - press)))
                time.sleep(0.05)
            # held still: the particle comes to sit under the mouse (a busy machine
            # delivers the last mouse events and draws the frames late). A hand at rest
            # trembles: about once a second the mouse moves a pixel and back, which sends
            # its position again if the drag's last move did not arrive (seen once, under
            # load: the particle stayed at the last-but-one position for 20 s).
            last_held: list[dict] = []
            polls = itertools.count(1)

            def arrived():
                if next(polls) % 10 == 0:  # about once a second
                    page.mouse.move(*(release + (1.0, 0.0)))
                    page.mouse.move(*release)
                state = read_state(state_file)
                if state is None or state["held"] is None:
                    return None
                last_held.append(state)
                pixel = np.array(state["pixels"][state["held"]])
                return state if np.abs(on_page(pixel) - release).max() <= 3.0 else None

            try:
                held = wait_until(arrived, 20, "the held particle reaching the mouse")
            except TimeoutError:
                if not last_held:
                    raise
                held = last_held[-1]  # the assertions below say where it is
            on_screen = on_page(np.array(held["pixels"][particle]))
            page.mouse.up()
        except Exception:
            page.screenshot(path=tmp_path / "page.png")
            raise
        finally:
            browser.close()
    assert held["held"] == particle  # the particle under the mouse was taken
    assert np.linalg.norm(on_screen - press) > 100.0  # it came along
    age = time.time() - held["written"]  # a stalled kernel stops writing
    np.testing.assert_allclose(
        on_screen, release, atol=3.0, err_msg=f"the kernel's last report is {age:.1f} s old"
    )  # and sits under the mouse
