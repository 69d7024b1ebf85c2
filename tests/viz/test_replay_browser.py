"""The replay page in headless Chromium, offline, from file://: it draws, plays, scrubs and
orbits, and asks the network for nothing; a keyboard alone works it, its landmark, heading
and controls have names, and a reader who asked for reduced motion finds it paused."""

import time

import pytest
from browser import launch, needs

import msdlab as msd
from msdlab import viz
from msdlab.scenes import gallery

pytestmark = [*needs("playwright"), pytest.mark.timeout(120)]


@pytest.fixture(scope="module")
def replay_file(tmp_path_factory):
    body = msd.Body.grid((4, 4, 4), spacing=0.1, stiffness=800.0)
    body.positions += (0.0, 0.3, 0.0)
    gravity = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground(0.0)]
    run = msd.Simulation(body, msd.Verlet(0.01), dt=2e-3, forces=gravity).run(
        steps=300, record_every=10
    )
    return viz.save_animation(run, tmp_path_factory.mktemp("replay") / "cube.html", fps=30)


def test_the_replay_page_plays_scrubs_and_orbits_offline(replay_file):
    from playwright.sync_api import sync_playwright

    requests: list[str] = []
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            context = browser.new_context()
            context.set_offline(True)
            page = context.new_page()
            page.on("request", lambda request: requests.append(request.url))
            errors: list[str] = []
            page.on("pageerror", lambda error: errors.append(str(error)))
            page.goto(replay_file.as_uri())
            status = page.locator(".msdlab-status")
            page.wait_for_function("() => window.msdlabViews?.[0]?.stats.drawn > 5")
            first = int(status.get_attribute("data-frame"))
            time.sleep(0.5)
            assert int(status.get_attribute("data-frame")) != first  # it plays
            page.get_by_text("❚❚ pause").click()
            scrub = page.locator(".msdlab-scrub")
            scrub.evaluate("(s) => { s.value = 7; s.dispatchEvent(new Event('input')); }")
            time.sleep(0.2)
            assert status.get_attribute("data-frame") == "7"  # scrubbed, and paused there
            azimuth = page.evaluate("() => window.msdlabViews[0].camera.azimuth")
            box = page.locator(".msdlab-canvas").bounding_box()
            page.mouse.move(box["x"] + 5, box["y"] + 5)  # a corner: no particle there
            page.mouse.down()
            page.mouse.move(box["x"] + 105, box["y"] + 5, steps=5)
            page.mouse.up()
            assert page.evaluate("() => window.msdlabViews[0].camera.azimuth") != azimuth
        finally:
            browser.close()
    assert not errors
    assert all(url.startswith(("file:", "blob:", "data:")) for url in requests), requests


def test_the_replay_page_is_named_and_worked_by_keys(replay_file):
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page()
            page.goto(replay_file.as_uri())
            page.wait_for_function("() => window.msdlabViews?.[0]?.stats.drawn > 0")
            assert page.get_by_role("main").get_by_role("heading", level=1).count() == 1
            scrub = page.get_by_role("slider", name="frame of the replay")
            status = page.locator(".msdlab-status")
            page.locator(".msdlab-live").focus()
            page.keyboard.press("Space")  # it played by itself: a key pauses it
            assert page.get_by_role("button", name="play the replay (space)").count() == 1
            page.keyboard.press("Home")
            page.keyboard.press("ArrowRight")
            page.keyboard.press("ArrowRight")
            page.wait_for_function("() => document.querySelector('.msdlab-scrub').value === '2'")
            assert status.get_attribute("data-frame") == "2"
            assert scrub.get_attribute("aria-valuetext").endswith("frame 3 of 31")
            assert status.inner_text().endswith(" · frame 3 of 31")  # the time, then the frame
            page.keyboard.press("End")
            page.wait_for_function("() => document.querySelector('.msdlab-scrub').value === '30'")
            page.keyboard.press("Tab")  # on to the body, the play button and the scrubber
            page.keyboard.press("Tab")
            assert page.evaluate("() => document.activeElement.textContent") == "▶ play"
            still = browser.new_page(reduced_motion="reduce")
            still.goto(replay_file.as_uri())
            still.wait_for_function("() => window.msdlabViews?.[0]?.stats.drawn > 5")
            assert still.locator(".msdlab-status").get_attribute("data-frame") == "0"
            assert still.get_by_role("button", name="play the replay (space)").count() == 1
        finally:
            browser.close()


# every stroke of the canvas: its width, whether dashed, its colour (springs' and others')
RECORD_STROKES = """
window.strokes = [];
const stroke = CanvasRenderingContext2D.prototype.stroke;
CanvasRenderingContext2D.prototype.stroke = function (...path) {
  window.strokes.push([this.lineWidth, this.getLineDash().length > 0, this.strokeStyle]);
  return stroke.apply(this, path);
};
"""


def test_the_replay_page_draws_springs_by_strain_in_lines_and_words(tmp_path):
    """The sagging mesh's springs are drawn in their class's width and dash (squeezed
    thin and dashed, stretched thick), and the key says so to the eye and in words."""
    from playwright.sync_api import sync_playwright

    run = gallery.mesh().run(steps=200, record_every=20)
    replay_file = viz.save_animation(run, tmp_path / "mesh.html")

    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page(reduced_motion="reduce")
            page.add_init_script(RECORD_STROKES)
            page.goto(replay_file.as_uri())
            page.wait_for_function("() => window.msdlabViews?.[0]?.stats.drawn > 0")
            page.locator(".msdlab-live").focus()
            page.keyboard.press("End")  # the mesh sagging: its rows stretched, columns squeezed
            page.wait_for_function("() => window.msdlabViews[0].stats.drawn > 1")
            scene = page.evaluate("() => window.msdlabViews[0].painter.scene")
            strokes = page.evaluate("() => window.strokes")
            key = page.locator(".msdlab-key")
            shown, said = key.inner_text(), key.locator(".msdlab-hidden").inner_text()
        finally:
            browser.close()
    colours = set(scene["colours"])
    springs = {(width, dashed) for width, dashed, colour in strokes if colour in colours}
    classes = {(s["width"], bool(s["dash"])) for s in scene["strokes"]}
    assert springs == classes  # squeezed, near rest and stretched
    assert all(name in shown for name in ("stretched", "near rest length", "squeezed"))
    assert said == scene["key"] and "thin dashed" in said


def test_a_dense_bodys_pixel_lines_are_dashed_plain_or_thick_by_class(tmp_path):
    """Over 3000 springs the page writes 1-px lines into the pixels: a squeezed spring's is
    dashed (3 pixels of 5), a stretched one's 2 px wide."""
    from playwright.sync_api import sync_playwright

    body = msd.Body.grid((30, 30), spacing=0.1, stiffness=800.0, neighbours=(1, 2))
    run = msd.Simulation(body, msd.Verlet(), dt=1e-3).run(steps=2, record_every=1)
    page_file = viz.save_animation(run, tmp_path / "net.html")
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            page = browser.new_page(reduced_motion="reduce")
            page.goto(page_file.as_uri())
            page.wait_for_function("() => window.msdlabViews?.[0]?.stats.drawn > 0")
            painted = page.evaluate(
                """() => [0, 1, 2].map((stroke) => {
                  const pixels = window.msdlabViews[0].painter.pixels;
                  pixels.clear();
                  pixels.line(10, 10, 59, 10, 0xff000000, stroke);  // 50 px along x
                  return pixels.words.filter((word) => word === 0xff000000).length; })"""
            )
        finally:
            browser.close()
    assert painted == [30, 50, 100]
