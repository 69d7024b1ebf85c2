"""What the live widget shows, counted in the page: new pictures a second, their gaps,
the pace the engine keeps, and the energy books of a drag.

Runs JupyterLab and headless Chromium (as tests/viz/test_widget_browser.py does), shows
each case with `viz.show` in a fresh notebook, presses reset (the run from its start)
and counts, over ``--seconds``:

- frames: the page's requestAnimationFrame callbacks a second;
- new pictures: frames showing positions that differ from the frame before (what the
  eye sees move), and the longest gap between two of them and the gaps over 50 ms;
- states shown (frames showing a new state) and received from the kernel, a second;
- pace: the share of the asked steps the engine did (1.00: it keeps up);
- Chromium's CPU time (psutil, which ipykernel installs).

For the mesh it then presses on a particle and moves the mouse around a circle for four
seconds, and reports what the page counted while the particle was dragged (new pictures a
second, the longest gap, the gaps over 50 ms), the delays from a mouse move (the event's
time stamp) to the frame drawing the held particle at the hand and to the first positions
from the engine with it there, and the drag's energy drift: the change of the total the
energy panel shows (in the body plus all taken out less the hand's work) over the hand's
work (the "hand's work" bar's change).
The ceiling: requestAnimationFrame callbacks a second of an empty page in the same
browser, measured before each case; and the machine's load average (`os.getloadavg`).

    python benchmarks/live_view.py [--seconds 6] [--cases mesh,cube10,cube20,grid10] [--plain]

JupyterLab runs as an installed msdlab sets it up: with the server extension
`msdlab.jupyter_extension`, whose kernel websockets send each message at once (TCP no-delay).
``--plain`` starts it with the server's own websocket instead (Nagle's algorithm).
Headless Chromium with --disable-gpu draws on the CPU and paces requestAnimationFrame
at the display's 60 Hz at most, so 60 a second is the ceiling here.
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

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from browser import jupyterlab_server, launch, run_notebook

# the server's own kernel websocket, named: the extension then leaves it in place
PLAIN = "jupyter_server.services.kernels.connection.channels.ZMQChannelsWebsocketConnection"
KERNEL = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
GRID = (
    "msd.Simulation(msd.Body.grid((10, 10, 10), spacing=0.1, stiffness=5000.0, "
    "neighbours=(1, 2, 3)), msd.Verlet(damping=0.01), dt=1e-3, "
    "forces=[msd.Gravity((0, -9.81, 0)), msd.Ground(height=0.0)])"
)
CASES = {  # label, the simulation, steps a second (None: real time)
    "mesh": ("gallery mesh (2-D, 100 particles)", "SCENES['mesh'].build()", 60),
    "cube10": ("jelly cube 10³ (3-D)", "SCENES['jelly-cube'].build(size=10)", 60),
    "cube20": ("jelly cube 20³ (3-D)", "SCENES['jelly-cube'].build(size=20)", 60),
    "grid10": ("Body.grid 10³, dt = 1e-3, real time", GRID, None),
}
CELL = """\
import msdlab as msd
from msdlab import viz
from msdlab.scenes import SCENES

live = viz.show({build}, steps_per_second={pace})
"""
EMPTY_RATE = """(ms) => new Promise((done) => { let n = 0; const t0 = performance.now();
const frame = (t) => { n++; if (t - t0 < ms) requestAnimationFrame(frame);
  else done((1000 * n) / (t - t0)); };
requestAnimationFrame(frame); })"""
DELAYS = """() => { const s = window.msdlabViews.at(-1).stats;
return [s.drawDelays, s.engineDelays]; }"""
# a page without new-picture counts (an older live.js) counts the pictures drawn
COUNTS = """() => { const v = window.msdlabViews.at(-1), s = v.stats;
return { frames: s.frames, pictures: s.pictures ?? s.drawn, updates: s.updates,
  received: s.received ?? s.updates,
  times: s.pictureTimes ?? null, pace: Number(v.status.dataset.pace ?? NaN),
  now: performance.now() }; }"""
BOOKS = """() => { const c = document.querySelector('.msdlab-energy');
return [Number(c.dataset.total), JSON.parse(c.dataset.bars)["hand's work"] ?? 0]; }"""


# a hand moving the mouse around a circle, its moves made in the page at 60 a second (as a
# mouse's are: Chromium sends one a frame), as one call: from Python, each move would be a
# round trip to the browser, a dozen a second on a loaded machine
HAND = """([x, y, radius, ms]) => new Promise((done) => {
const canvas = document.querySelector('.msdlab-canvas'), t0 = performance.now();
let moves = 0;
const move = () => { const t = performance.now() - t0, angle = 4 * Math.PI * t / ms;
  canvas.dispatchEvent(new PointerEvent('pointermove', { pointerId: 1, bubbles: true,
    clientX: x + radius * (Math.cos(angle) - 1), clientY: y + radius * Math.sin(angle) }));
  moves++;
  if (t < ms) setTimeout(move, 1000 / 60); else done(moves / (t / 1000)); };
move(); })"""


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


def page_counts(page, seconds: float) -> dict:
    """A second's frames, new pictures and updates over ``seconds`` (`counted_between`);
    Chromium's CPU (ms a second, all its processes)."""
    before, cpu = page.evaluate(COUNTS), browser_cpu()
    time.sleep(seconds)
    after, cpu = page.evaluate(COUNTS), browser_cpu() - cpu
    counts = counted_between(before, after)
    return {**counts, "cpu": 1000 * cpu / counts["seconds"]}


def counted_between(before: dict, after: dict) -> dict:
    """A second's frames, new pictures and updates between two `COUNTS`; the longest gap
    between new pictures and the gaps over 50 ms (ms; None for a page that does not keep
    their times); the pace."""
    elapsed = (after["now"] - before["now"]) / 1000
    counted = ("frames", "pictures", "updates", "received")
    rates = {k: (after[k] - before[k]) / elapsed for k in counted}
    gaps = None
    if after["times"] is not None:
        times = np.array([t for t in after["times"] if t >= before["now"]])
        gaps = np.diff(np.concatenate([[before["now"]], times, [after["now"]]]))
    return {
        **rates,
        "longest gap": None if gaps is None else float(gaps.max()),
        "gaps over 50 ms": None if gaps is None else int(np.sum(gaps > 50)),
        "pace": after["pace"],
        "seconds": elapsed,
    }


def empty_page_rate(browser, seconds: float = 3.0) -> float:
    """requestAnimationFrame callbacks a second of an empty page: the browser's ceiling."""
    page = browser.new_page()
    rate = page.evaluate(EMPTY_RATE, 1000 * seconds)
    page.close()
    return rate


def circular_drag(page, seconds: float = 4.0, radius: float = 60.0) -> dict:
    """Press on the mesh's top-right particle and move the mouse around a circle of
    ``radius`` px for ``seconds``; what the page counted while dragged (`counted_between`)
    and the mouse moves a second; the delays (ms) from the moves to the frame drawing the
    held particle at the hand and to the engine's positions with it there, and the
    energy panel's total and hand's work bar before the press and a second after release."""
    canvas = page.locator(".msdlab-canvas")
    canvas.scroll_into_view_if_needed()  # the reset button's click may have scrolled it away
    box = canvas.bounding_box()
    screen = np.array(
        page.evaluate("() => Array.from(window.msdlabViews.at(-1).painter.screen)")
    ).reshape(-1, 2) + (box["x"] + 1, box["y"] + 1)
    particle = screen[int(np.argmax(screen[:, 0] - screen[:, 1]))]
    books = page.evaluate(BOOKS)
    page.mouse.move(*particle)
    page.mouse.down()
    before = page.evaluate(COUNTS)
    moves = page.evaluate(HAND, [*particle.tolist(), radius, 1000 * seconds])
    during = counted_between(before, page.evaluate(COUNTS))
    page.mouse.up()
    time.sleep(1.0)
    drawn, engine = page.evaluate(DELAYS)
    total, work = np.array(page.evaluate(BOOKS)) - books
    return {"drawn": drawn, "engine": engine, "total": total, "work": work,
            "during": during, "moves": moves}  # fmt: skip


def shut_down_kernels(url: str, token: str) -> None:
    """Stop every kernel of the server: a case's stepping thread must not slow the next."""
    with urllib.request.urlopen(f"{url}/api/kernels?token={token}") as answer:
        kernels = json.load(answer)
    for kernel in kernels:
        request = urllib.request.Request(
            f"{url}/api/kernels/{kernel['id']}?token={token}", method="DELETE"
        )
        urllib.request.urlopen(request).close()


def show_case(browser, url: str, token: str, tmp: Path, key: str):
    """Show one case in a fresh notebook; the page, once it has drawn 20 states."""
    _, build, pace = CASES[key]
    notebook = nbformat.v4.new_notebook(metadata={"kernelspec": KERNEL})
    notebook.cells = [nbformat.v4.new_code_cell(CELL.format(build=build, pace=pace))]
    nbformat.write(notebook, tmp / f"{key}.ipynb")
    page = browser.new_page(viewport={"width": 1300, "height": 1000})
    page.set_default_timeout(120_000)
    run_notebook(page, url, token, f"{key}.ipynb")
    page.wait_for_function("() => window.msdlabViews?.at(-1)?.stats.updates > 20")
    return page


def warm_up(browser, url: str, token: str, tmp: Path) -> None:
    """Show the mesh for a few seconds, uncounted: the first notebook of a fresh JupyterLab
    shares the cores with the server's and the page's start (seen: 4 more gaps over 50 ms
    in the first case than in the same case second)."""
    page = show_case(browser, url, token, tmp, "mesh")
    time.sleep(3)
    page.close()
    shut_down_kernels(url, token)


def run_case(browser, url: str, token: str, tmp: Path, key: str, seconds: float) -> None:
    """Show one case in a fresh notebook and print what the page counted."""
    label = CASES[key][0]
    ceiling, load = empty_page_rate(browser), os.getloadavg()[0]
    page = show_case(browser, url, token, tmp, key)
    # from the start (the reset button), as every run: a gallery mesh lies still after 8 s,
    # and a body at rest shows no new pictures
    page.get_by_text("↺ reset").click()
    time.sleep(0.5)
    counts = page_counts(page, seconds)
    drag = None
    if key == "mesh":
        time.sleep(4.0)  # the mesh at rest (8 s after the reset): a particle where it is drawn
        drag = circular_drag(page)
    page.screenshot(path=f"/tmp/live_view_{key}.png")
    page.close()
    shut_down_kernels(url, token)
    gaps = (
        ""
        if counts["longest gap"] is None
        else f"longest gap {counts['longest gap']:.0f} ms, {counts['gaps over 50 ms']} over 50 ms; "
    )
    print(
        f"{label}: {counts['frames']:.1f} frames/s ({counts['frames'] / ceiling:.0%} of an "
        f"empty page's {ceiling:.1f}), {counts['pictures']:.1f} new pictures/s, "
        f"{counts['updates']:.1f} states shown/s of {counts['received']:.1f} received; "
        f"{gaps}pace {counts['pace']:.2f}; "
        f"Chromium's CPU {counts['cpu']:.0f} ms/s; load {load:.1f}",
        flush=True,
    )
    if drag is not None:
        during = drag["during"]
        print(
            f"  while dragged ({drag['moves']:.0f} mouse moves/s): {during['frames']:.1f} "
            f"frames/s, {during['pictures']:.1f} new pictures/s, {during['updates']:.1f} "
            f"states shown/s of {during['received']:.1f} received; longest gap "
            f"{during['longest gap']:.0f} ms, {during['gaps over 50 ms']} over 50 ms",
            flush=True,
        )
        for what in ("drawn", "engine"):
            if drag[what]:
                print(
                    f"  drag delay, {what}: median {np.median(drag[what]):.0f} ms, "
                    f"max {np.max(drag[what]):.0f} ms over {len(drag[what])} moves",
                    flush=True,
                )
        print(
            f"  drag's energy: the hand's work {drag['work']:.4g}, the total changed "
            f"{drag['total']:.4g} ({drag['total'] / drag['work']:+.1%} of the work)",
            flush=True,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=6.0)
    parser.add_argument("--cases", default=",".join(CASES))
    parser.add_argument("--plain", action="store_true", help="the server's own websocket")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    options = ["--ServerApp.kernel_websocket_connection_class=" + PLAIN] if args.plain else []
    with TemporaryDirectory() as folder, sync_playwright() as playwright:
        tmp = Path(folder)
        with jupyterlab_server(tmp, options=options) as (url, token):
            browser = launch(playwright)
            warm_up(browser, url, token, tmp)
            for key in args.cases.split(","):
                run_case(browser, url, token, tmp, key, args.seconds)
            browser.close()


if __name__ == "__main__":
    main()
