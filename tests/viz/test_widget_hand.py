"""The page draws a held particle at the hand at once, where `Grab` will pin it: the
front end (``live.js``) in headless Chromium with a stand-in for the kernel that records
what the page sends and never moves the body itself."""

import base64

import numpy as np
import pytest
from browser import launch, needs

from msdlab.scenes import SCENES
from msdlab.viz import frontend
from msdlab.viz.upright import resolve_up
from msdlab.viz.view import LIVE_STRAIN_LIMIT

pytestmark = [*needs("playwright"), pytest.mark.timeout(120)]

PAGE = """<!DOCTYPE html><html><body style="margin: 0"><div id="view"></div>
<script type="text/plain" id="module">MODULE</script>
<script type="module">
const text = document.getElementById("module").textContent;
const url = URL.createObjectURL(new Blob([text], { type: "text/javascript" }));
const { mountView } = await import(url);
const bytes = (text) => Uint8Array.from(atob(text), (c) => c.charCodeAt(0)).buffer;
window.start = (scene, arrays, positions) => {
  const engine = { x: new Float32Array(bytes(positions)), sent: [] };
  const source = {
    latest: () => engine.x,
    grab: (particle, target) => engine.sent.push(["grab", particle, target]),
    move: (target) => engine.sent.push(["move", target]),
    release: () => engine.sent.push(["release"]),
    stepping: () => true,
  };
  window.engine = engine;
  mountView(document.getElementById("view"), scene, {
    springs: new Int32Array(bytes(arrays.springs)),
    rest: new Float32Array(bytes(arrays.rest)),
    fixed: new Uint8Array(bytes(arrays.fixed)),
  }, source);
};
window.frames = (n) => new Promise((done) => {
  const next = () => (n-- > 0 ? requestAnimationFrame(next) : done());
  next();
});
</script></body></html>"""

HELD = """() => { const v = window.msdlabViews[0], p = v.held;
  return [p, v.painter.screen[2 * p], v.painter.screen[2 * p + 1], v.painter.depth[p]]; }"""
# where the last target sent to the engine is on the screen, and its depth
SENT = """() => { const v = window.msdlabViews[0], sent = window.engine.sent;
  const target = sent.findLast((m) => m[0] !== "release").at(-1);
  const screen = new Float32Array(2), depth = new Float32Array(1);
  v.camera.project(Float32Array.from(target), 1, screen, depth);
  return [screen[0], screen[1], depth[0]]; }"""


@pytest.mark.parametrize(
    "scene, build",
    [("mesh", {}), ("jelly-cube", {"size": 3})],
    ids=["2-D", "3-D"],
)
def test_the_held_particle_is_drawn_where_the_engine_is_told_to_pin_it(scene, build):
    from playwright.sync_api import sync_playwright

    sim = SCENES[scene].build(**build)
    up = resolve_up(None, sim, sim.body.dim)
    described = frontend.describe(sim, up=up, view=None, strain_limit=LIVE_STRAIN_LIMIT)
    arrays = {
        name: base64.b64encode(data).decode()
        for name, data in frontend.body_arrays(sim.body).items()
    }
    positions = base64.b64encode(sim.body.positions.astype(np.float32).tobytes()).decode()
    module = frontend.ESM.read_text()
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page(viewport={"width": 1000, "height": 700})
            errors: list[str] = []
            page.on("pageerror", lambda error: errors.append(str(error)))
            page.set_content(PAGE.replace("MODULE", module))
            page.wait_for_function("() => window.start")
            page.evaluate("([s, a, x]) => window.start(s, a, x)", [described, arrays, positions])
            page.wait_for_function("() => window.msdlabViews?.[0]?.stats.drawn > 0")
            box = page.locator(".msdlab-canvas").bounding_box()
            corner = np.array([box["x"] + 1, box["y"] + 1])  # the 1-px border
            screen = page.evaluate("() => Array.from(window.msdlabViews[0].painter.screen)")
            start = np.round(np.array(screen[:2]) + corner)  # at particle 0 or near it
            page.mouse.move(*start)
            page.mouse.down()
            particle, *_, depth = page.evaluate(HELD)
            hand = start + (40.0, -25.0)
            page.mouse.move(*hand)
            page.evaluate("() => window.frames(1)")

            # drawn at the hand in the next frame, while the engine has not moved it
            held, x, y, _ = page.evaluate(HELD)
            assert held == particle
            assert np.abs(np.array([x, y]) + corner - hand).max() < 0.5
            engine_x = page.evaluate("() => Array.from(window.engine.x)")
            assert np.allclose(engine_x, sim.body.positions.astype(np.float32).ravel())
            # the target sent to Grab is the point drawn (in 3-D on the plane facing the
            # camera through the particle where it was taken)
            sx, sy, sent_depth = page.evaluate(SENT)
            assert np.abs(np.array([sx, sy]) + corner - hand).max() < 0.5
            if sim.body.dim == 3:
                assert sent_depth == pytest.approx(depth, abs=1e-4)

            # let go: drawn at the hand until the engine has it there, then the engine's
            page.mouse.up()
            page.evaluate("() => window.frames(2)")
            assert page.evaluate("() => window.msdlabViews[0].hand") is not None
            page.evaluate(
                """(p) => { const e = window.engine, d = window.msdlabViews[0].camera.dim;
                const target = e.sent.findLast((m) => m[0] !== "release").at(-1);
                const x = Float32Array.from(e.x);
                for (let k = 0; k < d; k++) x[d * p + k] = target[k];
                e.x = x; }""",
                particle,
            )  # the engine's next positions: the particle where the hand left it
            page.evaluate("() => window.frames(2)")
            assert page.evaluate("() => window.msdlabViews[0].hand") is None
            x, y = page.evaluate(
                f"() => Array.from(window.msdlabViews[0].painter.screen.slice("
                f"{2 * particle}, {2 * particle + 2}))"
            )
            assert np.abs(np.array([x, y]) + corner - hand).max() < 0.5
        finally:
            browser.close()
    assert not errors
