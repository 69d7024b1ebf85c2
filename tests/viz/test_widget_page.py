"""The live widget's page (``live.js`` as anywidget renders it) in headless Chromium,
without JupyterLab: a stand-in for anywidget's model passes the page's requests to a real
`LiveView` and its new state back, as the kernel would. A person turns an instrument on
and reads it, drags a particle with a finger (pointer events), works the view with the
keyboard, downloads the run, and every control has a name a screen reader says."""

import base64

import numpy as np
import pytest
from browser import launch, needs

import msdlab as msd
from msdlab.viz import frontend
from msdlab.viz.widget import LiveView

pytestmark = [*needs("playwright", "anywidget"), pytest.mark.timeout(180)]

BYTES = ("springs", "rest", "fixed", "positions")  # traits sent as binary
CHANGING = ("error", "running", "speed", "tools")  # traits a frame may change
TRAITS = (*BYTES, "scene", "settings", "presets", *CHANGING)

PAGE = """<!DOCTYPE html><html><body style="margin: 0"><div id="view"></div>
<script type="text/plain" id="module">MODULE</script>
<script type="module">
const text = document.getElementById("module").textContent;
const url = URL.createObjectURL(new Blob([text], { type: "text/javascript" }));
const widget = (await import(url)).default;
const BYTES = BYTES_NAMES;
const decode = (text) => Uint8Array.from(atob(text), (c) => c.charCodeAt(0)).buffer;
/** anywidget's model, as far as the page uses it; what the page asks is kept in `asked`. */
class Model {
  constructor(state) { this.state = {}; this.handlers = {}; this.asked = []; this.put(state); }
  get(name) { return this.state[name]; }
  set(name, value) { this.state[name] = value; this.asked.push(["set", name, value]);
    this.fire("change:" + name); }
  save_changes() {}
  send(message) { this.asked.push(["send", message]); }
  on(event, f) { (this.handlers[event] ??= []).push(f); }
  off(event, f) { this.handlers[event] = (this.handlers[event] ?? []).filter((g) => g !== f); }
  fire(event, ...args) { for (const f of this.handlers[event] ?? []) f(...args); }
  /** The kernel's new state: bytes come as base64. */
  put(state) {
    for (const [name, value] of Object.entries(state)) {
      this.state[name] = BYTES.includes(name) ? decode(value) : value;
    }
    for (const name of Object.keys(state)) this.fire("change:" + name);
  }
  take() { const asked = this.asked; this.asked = []; return asked; }
}
window.start = (state) => {
  window.model = new Model(state);
  widget.render({ model: window.model, el: document.getElementById("view") });
};
</script></body></html>"""


def spring_mass() -> msd.Simulation:
    """0.5 kg on a 20 N/m spring of rest length 1 m, pinned at the top, pulled 0.1 m down."""
    body = msd.Body.from_arrays(
        [[0.0, 0.0], [0.0, -1.35]],
        [[0, 1]],
        masses=0.5,
        fixed=[True, False],
        stiffness=20.0,
        rest_lengths=[1.0],
    )
    return msd.Simulation(body, msd.Verlet(), dt=1e-3, forces=[msd.Gravity((0.0, -9.81))])


def state_of(view: LiveView, names=TRAITS) -> dict:
    """The traits ``names`` of ``view`` as the page's model holds them (bytes in base64)."""
    return {
        name: base64.b64encode(getattr(view, name)).decode()
        if name in BYTES
        else getattr(view, name)
        for name in names
    }


class Kernel:
    """Carries the page's requests to ``view`` and its states and changed traits back, a
    frame at a time."""

    def __init__(self, page, view: LiveView) -> None:
        self.page, self.view = page, view
        self.asked: list = []  # everything the page asked, in order
        view.send = self.to_page  # the view's messages: states, a download

    def to_page(self, content: dict, buffers: list) -> None:
        data = base64.b64encode(buffers[0]).decode()
        self.page.evaluate(
            "([c, d]) => window.model.fire('msg:custom', c, [Uint8Array.from(atob(d), "
            "(ch) => ch.charCodeAt(0)).buffer])",
            [content, data],
        )

    def frames(self, count: int = 1) -> None:
        """``count`` frames of 1/60 s: the page's requests done, steps, the state sent."""
        view = self.view
        for _ in range(count):
            # the page's frame first: Chromium hands it pointer moves at its frames
            self.page.evaluate("() => new Promise((done) => requestAnimationFrame(done))")
            asked = self.page.evaluate("() => window.model.take()")
            self.asked += asked
            for kind, *what in asked:
                if kind == "set":
                    setattr(view, *what)
                else:
                    view._on_message(view, what[0], [])
            if view.running:
                view.advance(1 / 60, budget=60)
            view.publish()
            self.page.evaluate("(s) => window.model.put(s)", state_of(view, CHANGING))


@pytest.fixture
def widget_page():
    """(page, kernel) with the widget of a spring-mass drawn."""
    yield from opened(spring_mass())


@pytest.fixture
def widget_page_in_air():
    """The same with the spring-mass in air drag (3/s)."""
    simulation = spring_mass()
    yield from opened(msd.Simulation(simulation.body, msd.Verlet(), dt=1e-3,
                                     forces=[*simulation.forces, msd.Drag(3.0)]))  # fmt: skip


def opened(simulation: msd.Simulation):
    """(page, kernel) with the widget of ``simulation`` drawn, until the test is done."""
    from playwright.sync_api import sync_playwright

    view = LiveView(simulation)
    page_text = PAGE.replace("MODULE", frontend.ESM.read_text()).replace(
        "BYTES_NAMES", repr(list(BYTES))
    )
    with sync_playwright() as playwright:
        browser = launch(playwright)
        try:
            context = browser.new_context(viewport={"width": 1000, "height": 900}, has_touch=True)
            page = context.new_page()
            errors: list[str] = []
            page.on("pageerror", lambda error: errors.append(str(error)))
            page.set_content(page_text)
            page.wait_for_function("() => window.start")
            page.evaluate("(s) => window.start(s)", state_of(view))
            page.wait_for_function("() => window.msdlabViews?.[0]?.stats.drawn > 0")
            yield page, Kernel(page, view)
            assert not errors
        finally:
            browser.close()


def test_a_toggle_shows_the_stopwatch_and_the_trace_reading_pythons(widget_page):
    page, kernel = widget_page
    view = kernel.view
    assert page.locator(".msdlab-stopwatch").is_hidden()
    page.get_by_role("button", name="stopwatch (simulated time)").click()
    page.get_by_role("button", name="trace of the particle last taken in hand").click()
    kernel.frames()
    assert view.tools["stopwatch"] and view.tools["trace"]
    page.get_by_role("button", name="start or stop the stopwatch").click()
    kernel.frames(90)  # 1.5 s of simulated time: one and a half periods
    page.get_by_role("button", name="start or stop the stopwatch").click()
    kernel.frames(3)
    shown = page.get_by_role("timer", name="stopwatch reading").text_content()
    assert float(shown) == pytest.approx(view.stopwatch.reading, abs=5e-4)
    assert view.stopwatch.reading == pytest.approx(1.5, abs=1 / 60)  # stopped a frame late
    period = float(page.locator(".msdlab-trace").get_attribute("data-period"))
    assert period == pytest.approx(2 * np.pi * np.sqrt(0.5 / 20.0), rel=1e-4)
    assert "period 0.9934" in page.locator(".msdlab-trace").get_attribute("aria-label")


def test_a_finger_drags_a_particle_with_pointer_events(widget_page):
    page, kernel = widget_page
    box = page.locator(".msdlab-canvas").bounding_box()
    corner = np.array([box["x"] + 1, box["y"] + 1])  # the 1-px border
    screen = np.array(page.evaluate("() => Array.from(window.msdlabViews[0].painter.screen)"))
    start = corner + screen[2:4]  # the hung mass
    touch = page.context.new_cdp_session(page)

    def finger(kind: str, at: np.ndarray) -> None:
        points = [] if kind == "touchEnd" else [{"x": float(at[0]), "y": float(at[1])}]
        touch.send("Input.dispatchTouchEvent", {"type": kind, "touchPoints": points})

    finger("touchStart", start)
    for fraction in np.linspace(0.2, 1.0, 5):
        finger("touchMove", start + fraction * np.array([60.0, 30.0]))
        kernel.frames()

    def asked() -> tuple[dict, list[dict]]:  # the grab, and the moves (the path) since
        sent = [what[0] for kind, *what in kernel.asked if kind == "send"]
        grab, *moves = [m for m in sent if m["type"] != "frames"]  # not the page's frame rate
        return grab, moves

    for _ in range(60):  # a second at most: the last moves go within 100 ms, played back at
        _, moves = asked()  # the finger's pace
        if sum(len(m["path"]) for m in moves) == 5 and kernel.view.hand.caught_up:
            break
        kernel.frames()
    grab, moves = asked()
    assert grab["type"] == "grab" and grab["particle"] == 1
    assert {m["type"] for m in moves} == {"move"}  # the finger's path, a few moves a message
    assert sum(len(m["path"]) for m in moves) == 5
    assert kernel.view.grab.particle == 1
    screen_now = page.evaluate(
        """(x) => { const out = new Float32Array(2), depth = new Float32Array(1);
        window.msdlabViews[0].camera.project(Float32Array.from(x), 1, out, depth);
        return Array.from(out); }""",
        kernel.view.sim.body.positions[1].tolist(),
    )
    assert np.abs(corner + screen_now - (start + (60.0, 30.0))).max() < 1.0  # under the finger
    finger("touchEnd", start)
    kernel.frames()
    assert kernel.view.grab.particle is None


def test_the_hands_quick_moves_reach_the_kernel_together_with_their_times(widget_page):
    """A mouse moved six times within a few ms: one message with the six moves, in order,
    each with its time (the kernel plays them back at the hand's pace), not six messages
    (each a request to the kernel and two status messages back)."""
    page, kernel = widget_page
    box = page.locator(".msdlab-canvas").bounding_box()
    screen = np.array(page.evaluate("() => Array.from(window.msdlabViews[0].painter.screen)"))
    start = [box["x"] + 1 + float(screen[2]), box["y"] + 1 + float(screen[3])]  # hung mass
    page.mouse.move(*start)
    page.mouse.down()
    page.evaluate(
        """(start) => { const canvas = document.querySelector('.msdlab-canvas');
        for (let k = 1; k <= 6; k++) canvas.dispatchEvent(new PointerEvent('pointermove',
          { pointerId: 1, clientX: start[0] + 5 * k, clientY: start[1], bubbles: true })); }""",
        start,
    )
    page.wait_for_timeout(250)  # longer than the 100 ms the page gathers moves over
    kernel.frames()
    sent = [what[0] for kind, *what in kernel.asked if kind == "send"]
    moves = [m for m in sent if m["type"] == "move"]
    assert len(moves) == 1 and len(moves[0]["path"]) == 6
    times = [move[0] for move in moves[0]["path"]]
    assert times == sorted(times)
    xs = [move[1] for move in moves[0]["path"]]
    assert np.all(np.diff(xs) > 0)  # the moves in the order made
    page.mouse.up()


def test_the_keyboard_pauses_steps_resets_and_sets_the_speed(widget_page):
    page, kernel = widget_page
    view = kernel.view
    page.locator(".msdlab-live").focus()
    page.keyboard.press("Space")
    kernel.frames()
    assert not view.running
    steps = view.sim.step_count
    page.keyboard.press("s")
    kernel.frames()
    assert view.sim.step_count == steps + 1
    page.keyboard.press("]")
    page.keyboard.press("]")
    kernel.frames()
    assert view.speed == pytest.approx(1.2)
    page.keyboard.press("r")
    kernel.frames()
    assert view.sim.step_count == 0
    assert page.get_by_role("button", name="pause or run (space)").text_content() == "▶ run"


def test_the_run_downloads_as_npz_from_its_button(widget_page, tmp_path):
    page, kernel = widget_page
    kernel.frames(30)
    shown = kernel.view.sim.time  # the run shown when the button is pressed
    with page.expect_download() as download:
        page.get_by_role("button", name="download the run shown").filter(has_text="NPZ").click()
        kernel.frames()
    path = tmp_path / download.value.suggested_filename
    download.value.save_as(path)
    run = np.load(path)
    assert path.name == "msdlab-run.npz"
    assert run["time"][-1] == shown and len(run["time"]) == 31  # the start and 30 frames
    assert np.ptp(run["positions"][:, 1, 1]) > 0.01  # the mass moved


def test_every_control_has_a_name_a_screen_reader_says(widget_page):
    page, _ = widget_page
    unnamed = page.evaluate(
        """() => Array.from(document.querySelectorAll(
            '.msdlab-live button, .msdlab-live input, .msdlab-live canvas, [tabindex]'))
          .filter((node) => !(node.getAttribute('aria-label') || '').trim())
          .map((node) => node.outerHTML.slice(0, 80))"""
    )
    assert unnamed == []
    controls = page.locator(".msdlab-live button, .msdlab-live input")
    assert controls.count() >= 15  # run, step, reset, speed, 4 sliders, 5 tools, 2 + 4 + 2 more
    for name in ("one step (s)", "back to the start (r)", "stiffness k", "gravity |g|"):
        assert page.get_by_label(name, exact=True).count() == 1


BAR_PIXELS = """() => { const c = document.querySelector('.msdlab-energy');
const names = [...Object.keys(JSON.parse(c.dataset.bars)), "total"];
const height = 300 / names.length, g = c.getContext('2d');
return Object.fromEntries(names.map((name, i) => [name,
  Array.from(g.getImageData(11, Math.round(8 + i * height + 13 + (height - 18) / 2), 1, 1)
    .data.slice(0, 3))])); }"""


def test_the_hands_work_has_a_bar_of_its_own_colour(widget_page_in_air, tmp_path):
    """Dragged, then let go in air drag, the hand's work and the drag's share are two bars in
    two colours: the hand's the colour of the ring round the particle in hand."""
    page, kernel = widget_page_in_air
    box = page.locator(".msdlab-canvas").bounding_box()
    screen = np.array(page.evaluate("() => Array.from(window.msdlabViews[0].painter.screen)"))
    start = np.array([box["x"] + 1 + float(screen[2]), box["y"] + 1 + float(screen[3])])
    page.mouse.move(*start)
    page.mouse.down()
    for angle in np.linspace(0.0, 3 * np.pi, 60):  # one and a half circles: it ends lifted
        page.mouse.move(*(start + 40.0 * np.array([np.sin(angle), 1 - np.cos(angle)])))
        kernel.frames()
    page.mouse.up()
    kernel.frames(60)  # let go, it swings in the air: the drag takes its share
    page.locator(".msdlab-energy").screenshot(path=tmp_path / "bars.png")
    colours = page.evaluate(BAR_PIXELS)
    assert colours["hand's work"] == [0xE8, 0xA3, 0x17]  # the held particle's ring
    assert colours["drag"] == [0xD6, 0x27, 0x28]
    others = [colour for name, colour in colours.items() if name != "hand's work"]
    assert colours["hand's work"] not in others


FOCUS_RING = """() => { const v = window.msdlabViews[0], p = v.focus;
const [x, y] = [v.painter.screen[2 * p] + 12, v.painter.screen[2 * p + 1]];
return Array.from(v.canvas.getContext('2d').getImageData(Math.round(x), Math.round(y), 1, 1)
  .data.slice(0, 3)); }"""


def told(page, kernel, words: str) -> str:
    """The body's line once it holds ``words`` (said every 2 s at most), frames running."""
    for _ in range(40):
        line = page.locator(".msdlab-told").text_content()
        if words in line:
            return line
        kernel.frames()
        page.wait_for_timeout(100)
    raise AssertionError(f"the live region never said {words!r}: {line!r}")


def test_the_keyboard_alone_takes_a_particle_moves_it_and_hears_the_body(widget_page):
    """Tab to the body, the arrow key to the hung mass, Enter takes it, three presses of the
    right arrow move it, Enter lets go; the live regions say each and what the body does."""
    page, kernel = widget_page
    view = kernel.view
    page.locator(".msdlab-live").focus()
    page.keyboard.press("Tab")  # the body's canvas
    assert page.evaluate("() => document.activeElement.className") == "msdlab-canvas"
    said = page.locator(".msdlab-said")
    assert said.text_content().startswith("particle 0 of 2, pinned")
    page.keyboard.press("ArrowDown")
    assert said.text_content() == "particle 1 of 2, at x 0, y -1.35 m"
    kernel.frames()
    ring = page.evaluate(FOCUS_RING)
    assert ring[2] > 150 and ring[0] < 80  # the focus ring's blue, beside the mass
    page.keyboard.press("Enter")
    step = float(said.text_content().split("move it by ")[1].split()[0])
    for _ in range(3):
        page.keyboard.press("ArrowRight")
    assert said.text_content().startswith("particle 1 at x ")
    for _ in range(12):  # the moves go within 100 ms, each played back over 50 ms at most
        kernel.frames()
        page.wait_for_timeout(20)
    assert view.grab.particle == 1
    assert view.sim.body.positions[1, 0] == pytest.approx(3 * step, abs=1e-6)
    assert "Particle 1 in hand at x " in told(page, kernel, "in hand")
    page.keyboard.press("Enter")
    assert said.text_content().startswith("let go of particle 1")
    kernel.frames(3)
    assert view.grab.particle is None
    assert told(page, kernel, "The body is swinging.")
    page.keyboard.press("d")
    kernel.frames()
    full = page.locator(".msdlab-full")
    assert full.is_visible()
    assert full.text_content().startswith(
        "A 2-D body of 2 particles and 1 spring, 1 of them pinned."
    )
    page.keyboard.press("a")  # a tone: two octaves above 220 Hz when all is kinetic
    kernel.frames(2)
    page.evaluate("() => new Promise((done) => requestAnimationFrame(done))")  # the last shown
    assert page.get_by_role("button", name="a tone").get_attribute("aria-pressed") == "true"
    e = view.energy
    share = e["kinetic"] / (e["kinetic"] + e["elastic"] + abs(e["gravitational"]))
    tone = page.evaluate("() => window.msdlabViews[0].tone.frequency")
    assert tone == pytest.approx(220 * 4**share, rel=1e-6) and tone > 221  # it swings
    page.keyboard.press("p")  # pins the hung mass where it is
    kernel.frames()
    assert view.sim.body.fixed[1]
