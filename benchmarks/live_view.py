"""Frames per second of the live widget, counted in the page, and the delay of a drag.

Runs JupyterLab and headless Chromium (as tests/viz/test_widget_browser.py does), shows
each case with `viz.show` in a fresh notebook, at 60 steps a second (the gallery's frames;
the template cube's steps of dt = 0.4, whose real time would be 2.5 steps a second), and
counts, over ``--seconds``, the page's frames (requestAnimationFrame callbacks), the
pictures it drew (in frames where positions, camera or hand changed) and the new positions
it received from Python, and the CPU time Chromium's processes took (psutil, which
ipykernel installs): what the page costs a loaded machine, whatever the frame rate.
For the mesh it then presses on a particle and moves the mouse 15 px every 0.3 s, and
gives two delays from a mouse move (the event's time stamp): to the end of the frame
that draws the held particle at the hand (the page draws it there itself, where `Grab`
will pin it), and to the first positions from the engine with the particle there (the
page's request, the server, the kernel, a step, the positions back).
The ceiling: requestAnimationFrame callbacks a second of an empty page in the same
browser, measured before each case; and the machine's load average (`os.getloadavg`).
Beside it, the matplotlib view measured on the Agg canvas alone: the time of one frame
(the steps of a frame and a full redraw), an upper bound of ipympl's frame rate, which
then encodes a PNG per frame and sends it over the websocket.

    python benchmarks/live_view.py [--seconds 10] [--cases mesh,cube10,cube20]

Headless Chromium with --disable-gpu draws on the CPU and paces requestAnimationFrame at
the display's 60 Hz at most, so 60 fps is the ceiling here (less on a loaded machine).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import urllib.request
from pathlib import Path
from tempfile import TemporaryDirectory

import nbformat
import numpy as np
import psutil

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "viz"))
from browser import jupyterlab_server, launch, run_notebook

KERNEL = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
CASES = {
    "mesh": ("gallery mesh (2-D, 100 particles)", "SCENES['mesh'].build()", 60),
    "cube10": ("jelly cube 10³ (3-D)", "SCENES['jelly-cube'].build(size=10)", 60),
    "cube20": ("jelly cube 20³ (3-D)", "SCENES['jelly-cube'].build(size=20)", 60),
}
CELL = """\
from msdlab import viz
from msdlab.scenes import SCENES

live = viz.show({build}, steps_per_second={pace})
"""
EMPTY_RATE = """(ms) => new Promise((done) => { let n = 0; const t0 = performance.now();
const frame = (t) => { n++; if (t - t0 < ms) requestAnimationFrame(frame);
  else done((1000 * n) / (t - t0)); };
requestAnimationFrame(frame); })"""
# (an older live.js, before the page drew the hand itself, had only `delays`: the engine's)
DELAYS = """() => { const s = window.msdlabViews.at(-1).stats;
return [s.drawDelays ?? [], s.engineDelays ?? s.delays]; }"""
COUNTS = "() => {const s = window.msdlabViews.at(-1).stats; return [s.frames, s.drawn, s.updates, \
performance.now()];}"


def browser_cpu() -> float:
    """CPU seconds used so far by the Chromium processes this script started."""
    total = 0.0
    for child in psutil.Process().children(recursive=True):
        try:
            if "chrom" in child.name().lower():
                total += sum(child.cpu_times()[:2])  # user, system
        except psutil.NoSuchProcess:
            pass
    return total


def page_rate(page, seconds: float) -> np.ndarray:
    """(frames, pictures drawn, position updates) a second in the page over ``seconds``,
    and the CPU time of Chromium (ms a second, all its processes): the page draws a picture
    in a frame when something changed (positions, camera, hand)."""
    *counts0, t0 = page.evaluate(COUNTS)
    cpu0 = browser_cpu()
    time.sleep(seconds)
    *counts1, t1 = page.evaluate(COUNTS)
    cpu = browser_cpu() - cpu0
    elapsed = (t1 - t0) / 1000
    return np.array([*((np.array(counts1) - counts0) / elapsed), 1000 * cpu / elapsed])


def empty_page_rate(browser, seconds: float = 3.0) -> float:
    """requestAnimationFrame callbacks a second of an empty page: the browser's ceiling."""
    page = browser.new_page()
    rate = page.evaluate(EMPTY_RATE, 1000 * seconds)
    page.close()
    return rate


def drag_delays(page, moves: int = 12) -> tuple[list[float], list[float]]:
    """Delays (ms) from mouse moves to the frame drawing the held particle at the hand, and
    to the engine's positions showing it there."""
    canvas = page.locator(".msdlab-canvas")
    box = canvas.bounding_box()
    screen = np.array(
        page.evaluate("() => Array.from(window.msdlabViews.at(-1).painter.screen)")
    ).reshape(-1, 2) + (box["x"] + 1, box["y"] + 1)
    particle = screen[int(np.argmax(screen[:, 0] - screen[:, 1]))]
    page.mouse.move(*particle)
    page.mouse.down()
    time.sleep(0.5)
    for i in range(1, moves + 1):
        page.mouse.move(particle[0] - 15 * i, particle[1] - 5 * i)
        time.sleep(0.3)
    page.mouse.up()
    time.sleep(0.5)
    drawn, engine = page.evaluate(DELAYS)
    return drawn, engine


def shut_down_kernels(url: str, token: str) -> None:
    """Stop every kernel of the server: a case's stepping thread must not slow the next."""
    with urllib.request.urlopen(f"{url}/api/kernels?token={token}") as answer:
        kernels = json.load(answer)
    for kernel in kernels:
        request = urllib.request.Request(
            f"{url}/api/kernels/{kernel['id']}?token={token}", method="DELETE"
        )
        urllib.request.urlopen(request).close()


def agg_frame_time(build: str, pace: float | None, frames: int = 10) -> float:
    """Seconds per frame of the matplotlib view on Agg: a frame's steps and a full draw."""
    import matplotlib

    matplotlib.use("Agg")
    from msdlab import viz
    from msdlab.scenes import SCENES  # noqa: F401  (used by ``build``)

    sim = eval(build)
    dragger = viz.Dragger(sim, steps_per_second=pace or 1.0 / sim.dt)
    dragger.advance()  # compiles
    dragger.ax.figure.canvas.draw()
    start = time.perf_counter()
    for _ in range(frames):
        time.sleep(1 / 60)  # a frame's worth of steps are due
        dragger.advance()
        dragger.ax.figure.canvas.draw()
    return (time.perf_counter() - start) / frames - 1 / 60


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--cases", default=",".join(CASES))
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    rows = []
    with TemporaryDirectory() as folder, sync_playwright() as playwright:
        tmp = Path(folder)
        with jupyterlab_server(tmp) as (url, token):
            browser = launch(playwright)
            for key in args.cases.split(","):
                label, build, pace = CASES[key]
                ceiling, load = empty_page_rate(browser), os.getloadavg()[0]
                notebook = nbformat.v4.new_notebook(metadata={"kernelspec": KERNEL})
                notebook.cells = [nbformat.v4.new_code_cell(CELL.format(build=build, pace=pace))]
                nbformat.write(notebook, tmp / f"{key}.ipynb")
                page = browser.new_page(viewport={"width": 1300, "height": 1000})
                page.set_default_timeout(120_000)
                run_notebook(page, url, token, f"{key}.ipynb")
                page.wait_for_function("() => window.msdlabViews?.at(-1)?.stats.updates > 20")
                time.sleep(2)
                fps, drawn_rate, updates, cpu = page_rate(page, args.seconds)
                drawn, engine = drag_delays(page) if key == "mesh" else ([], [])
                page.screenshot(path=f"/tmp/live_view_{key}.png")
                page.close()
                shut_down_kernels(url, token)
                agg = agg_frame_time(build, pace)
                rows.append((label, fps, updates, drawn, engine, agg))
                print(
                    f"{label}: page {fps:.1f} fps ({fps / ceiling:.0%} of an empty page's "
                    f"{ceiling:.1f}), {drawn_rate:.1f} pictures/s, {updates:.1f} updates/s, "
                    f"Chromium's CPU {cpu:.0f} ms/s; "
                    f"matplotlib on Agg {1000 * agg:.0f} ms/frame = {1 / agg:.1f} fps; "
                    f"load {load:.1f}",
                    flush=True,
                )
                for what, delays in (("drawn at the hand", drawn), ("engine there", engine)):
                    if delays:
                        print(
                            f"  drag delay, {what}: median {np.median(delays):.0f} ms, "
                            f"max {np.max(delays):.0f} ms over {len(delays)} moves",
                            flush=True,
                        )
            browser.close()


if __name__ == "__main__":
    main()
