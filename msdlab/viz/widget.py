"""The live view in a notebook: an anywidget whose page draws while Python steps.

The browser (``live.js``) draws at its own frame rate and never waits for Python.
Python steps the simulation in a background thread at the scene's pace
(``steps_per_second`` × ``speed``: 60 a second for the gallery, real time, 1/dt a
second, for physical scenes) and sends a state at the page's frame rate (which the
page reports; `FRAME_RATE` at most): one message per state, the positions as a
float32 buffer and, every `ENERGY_EVERY` states, the energies and the status line
inside the same message. The page queues the states and shows one a frame, so two
that arrive together are both shown. A thread rather than an asyncio task: the kernel's event loop
stops while a cell runs, and a thread also runs outside Jupyter (tests,
scripts); the kernel sends comm messages from any thread. What the page asks
(grab, move, release, step, reset, a slider, the stopwatch's buttons, an export, a pin,
a description)
arrives on the kernel's main thread and is queued, to be done by the stepping thread
between two steps; the hand's moves are played back to `Grab` one step at a time at the
pace the hand made them (`hand.HandPath`). The instruments turned on (`instruments`)
are read here and their readings ride in the states; every state sent is kept for
export (`export.Recording`). Every energy update carries the state in a line of words
(`words.brief`), which the page's live region reads out; asked, the next state carries
the whole state in words (`words.full`).
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import anywidget
import numpy as np
import traitlets

from .. import Gravity, Simulation, SimulationDiverged, kinetic_energy
from ..engine.model.units import SI
from ..interaction import Grab, Ground, Walls
from ..scenes.registry import Scene
from . import frontend, instruments, settings, words
from .export import Recording
from .hand import HandPath
from .upright import UPS, resolve_up
from .view import LIVE_STRAIN_LIMIT, spheres_of

FRAME_RATE = 60.0  # most states sent a second
SLOWEST = 5.0  # fewest states sent a second, whatever the page reports
ENERGY_EVERY = 4  # states sent per energy update (15 a second)
BUDGET = 0.75  # of the time between two states sent, spent stepping at most
KEEPS_PACE = 0.97  # a pace below this share of the one asked is shown in the status line
PACE_OVER = 10.0  # steps asked, at least, over which the pace kept is measured
PHASE = 0.5  # of a step owed at the start: the steps of a frame are not on a knife's edge
# requests done at the next state sent, not at once: a mouse moves 60 times a second,
# and a state sent for each move beside the paced ones would be more than the page can
# show (the page draws the held particle at the hand itself)
PACED = ("move", "frames")
_running: list[LiveView] = []  # views started by `show`, stopped when a new one starts


def floor_level(sim: Simulation, up: int) -> float | None:
    """The floor's height along axis ``up``: the ground's, or the walls' bottom; None
    without either."""
    for item in sim.constraints:
        if isinstance(item, Ground):
            return item.height / item.normal_of(sim.body)[up]
        if isinstance(item, Walls) and np.isfinite(item.lower[up]):
            return float(item.lower[up])
    return None


def ground_level(sim: Simulation, up: int) -> float:
    """The height (along axis ``up``) gravitational energy is counted from, as PhET does:
    the floor's (`floor_level`), else the lowest particle's now."""
    floor = floor_level(sim, up)
    return float(sim.body.positions[:, up].min()) if floor is None else floor


def velocities_now(sim: Simulation) -> np.ndarray:
    """The velocities at the positions' time, as the ledger takes them."""
    x, v = sim.body.positions, sim.body.velocities
    if sim.step_count == 0:
        return v
    return sim.integrator.velocity_at_positions(v, sim.dynamics.acceleration(x, v), sim.dt)


def energies(
    sim: Simulation,
    taken_at_start: dict[str, float],
    level: float = 0.0,
    v: np.ndarray | None = None,
) -> dict:
    """The ledger's energies of ``sim`` now (as `Simulation.run` records them, in the
    simulation's units, J in SI):
    kinetic, elastic, gravitational (counted from height ``level`` along gravity; ``zero``
    is the ledger's gravitational energy at that height), other potential, and what each
    mechanism took out since the view started; the time (s). ``v``: `velocities_now`,
    if the caller has them."""
    x = sim.body.positions
    v = velocities_now(sim) if v is None else v
    gravities = [f for f in sim.forces if isinstance(f, Gravity)]
    gravitational = sum(f.potential_energy(sim.body, x) for f in gravities)
    potential = sum(f.potential_energy(sim.body, x) for f in sim.forces)
    g = sum((f.g for f in gravities), np.zeros(sim.body.dim))
    zero = -float(np.sum(sim.body.masses)) * level * float(g[int(np.argmax(np.abs(g)))])
    return {
        "time": sim.time,
        "kinetic": kinetic_energy(sim.body, v),
        "elastic": sim.dynamics.elastic_energy(x),
        "gravitational": gravitational - zero,
        "zero": zero,
        "other": potential - gravitational,
        "dissipated": {
            name: value - taken_at_start.get(name, 0.0) for name, value in sim.dissipated.items()
        },
    }


class LiveView(anywidget.AnyWidget):
    """A simulation running in a notebook: drag particles, orbit (3-D), pause, step,
    reset, change settings with sliders, watch the energy bars.

    ``scene`` (a registered `Scene`) adds its build settings as sliders that rebuild it.
    ``steps_per_second`` defaults to real time (1/dt); ``view`` is (azimuth, elevation) in
    degrees and ``up`` the vertical axis (by default against gravity, `upright`).
    Energies are labelled in ``energy_unit``, by default the simulation's (`sim.units`:
    J in SI, px²/frame² for the gallery's unit masses in pixels and frames).
    """

    _esm = frontend.ESM
    scene = traitlets.Dict().tag(sync=True)
    springs = traitlets.Bytes().tag(sync=True)
    rest = traitlets.Bytes().tag(sync=True)
    fixed = traitlets.Bytes().tag(sync=True)
    positions = traitlets.Bytes().tag(sync=True)  # at the start; then in the states sent
    settings = traitlets.List().tag(sync=True)
    error = traitlets.Unicode().tag(sync=True)
    running = traitlets.Bool(True).tag(sync=True)
    speed = traitlets.Float(1.0).tag(sync=True)
    tools = traitlets.Dict().tag(sync=True)  # which instruments are shown: name -> on
    presets = traitlets.Dict().tag(sync=True)  # gravity presets, |g| in the scene's units

    def __init__(
        self,
        sim: Simulation,
        *,
        scene: Scene | None = None,
        steps_per_second: float | None = None,
        view: Sequence[float] | None = None,
        up: str | None = None,
        energy_unit: str | None = None,
    ) -> None:
        super().__init__()
        self.scene_entry, self.pace = scene, steps_per_second
        self._look = (view, up, energy_unit)
        self._commands: queue.SimpleQueue[Callable[[], None]] = queue.SimpleQueue()
        self._stop = threading.Event()
        self._wake = threading.Event()  # set by the page's requests and by `stop`
        self._thread: threading.Thread | None = None
        self._values: dict[str, float] = {}
        self._frames = 0
        self._moved = False  # the hand moved since the last frame
        self.hand: HandPath | None = None  # the held particle's path, played back
        self._letting_go = False  # the hand let go; the playback finishes its path first
        self.send_rate = FRAME_RATE  # states sent a second: the page's frame rate
        self.energy: dict = {}  # the energies of the last state sent (`energies`)
        self.status = ""  # the status line last sent
        self.achieved = 1.0  # steps done over steps asked since the last energy update
        self.stopwatch = instruments.Stopwatch(lambda: self.sim.time)
        self.readings: dict = {}  # what the instruments turned on read, as last sent
        self.in_words = ""  # the state in a line of words, as last sent (`words.brief`)
        self._describe = False  # the page asked for the whole state in words
        self.tools = {name: False for name in instruments.TOOLS}
        self.attach(sim)
        self.on_msg(self._on_message)

    # ------------------------------------------------------------------ the simulation
    def attach(self, sim: Simulation) -> None:
        """Show ``sim`` from now on (at the start, and after a rebuild)."""
        self.sim = sim
        self.grab = Grab()
        self.hand, self._letting_go = None, False
        sim.constraints.append(self.grab)
        self._start = settings.start_of(sim)
        self._initial = (sim.body.positions.copy(), sim.body.velocities.copy())
        self._taken = dict(sim.dissipated)
        up = resolve_up(self._look[1], sim, sim.body.dim)
        self._up = UPS.index(up)
        self._level = ground_level(sim, self._up)
        self._floor = floor_level(sim, self._up) is not None
        self._owed, self._clock = PHASE, time.perf_counter()
        self._asked = self._done = 0.0
        view, _, energy_unit = self._look
        live = settings.live_settings(sim)
        rebuild = (
            []
            if self.scene_entry is None
            else settings.scene_settings(self.scene_entry, {s.name for s in live})
        )
        for setting in rebuild:
            setting.value = self._values.get(setting.name, setting.value)
        with self.hold_sync():
            self.scene = frontend.describe(
                sim,
                up=up,
                view=view,
                strain_limit=LIVE_STRAIN_LIMIT,
                spheres=spheres_of(sim),
                energy_unit=energy_unit,
            )
            for name, data in frontend.body_arrays(sim.body).items():
                setattr(self, name, data)
            self.settings = [s.as_dict() for s in (*live, *rebuild)]
            self.error = ""
            self.positions = self._positions()
        self.set_up_instruments()
        self.publish()

    @property
    def steps_per_second(self) -> float:
        """The pace at speed 1: ``steps_per_second`` as given, or real time."""
        return self.pace if self.pace is not None else 1.0 / self.sim.dt

    def _positions(self) -> bytes:
        return self.sim.body.positions.astype(np.float32).tobytes()

    def publish(self, energy: bool = True) -> None:
        """Send the state: one message, the positions (a float32 buffer) and, if
        ``energy``, the energies and the status line (a layout of the page: the thread
        sends them every `ENERGY_EVERY` states). Every state sent is recorded for export
        with its velocities and energies (a force evaluation)."""
        content: dict = {"type": "state"}
        velocities = velocities_now(self.sim)
        self.energy = energies(self.sim, self._taken, self._level, velocities)
        self.recording.add(self.sim.time, self.sim.body.positions, velocities, self.energy)
        if energy or self._describe:
            summary = self.summary(velocities)
            self.in_words = content["words"] = words.brief(summary)
            if self._describe:
                content["full"], self._describe = words.full(summary), False
        if energy:
            content["energy"] = self.energy
            self.status = content["status"] = self.status_line()
            content["pace"] = self.achieved
        if any(self.tools.values()) or self.readings:  # once more, empty, when all go off
            self.readings = content["readings"] = self.measure() if any(self.tools.values()) else {}
        self.send(content, buffers=[self._positions()])

    def summary(self, velocities: np.ndarray) -> words.BodySummary:
        """The body now, for the words the page reads out (`words.summarise`)."""
        return words.summarise(
            self.sim,
            velocities,
            self.energy,
            springs=len(self.rest) // 4,  # float32 rest lengths, one a spring
            up=self._up,
            level=self._level,
            has_floor=self._floor,
            held=self.grab.particle,
            watched=self.steps_per_second * self.speed * self.sim.dt,
            energy_unit=self.scene["energy_unit"],
            stopped=self.error,
        )

    def status_line(self) -> str:
        """The time, the steps and, when the engine falls behind, the pace it keeps."""
        sim, unit = self.sim, self.scene["time_unit"]
        line = f"t = {sim.time:.4g} {unit}   steps {sim.step_count}"
        if self._asked >= PACE_OVER:
            self.achieved = min(1.0, self._done / self._asked)
            self._asked = self._done = 0.0
        if self.running and self.achieved < KEEPS_PACE:
            asked = "real time" if self.pace is None else f"{self.steps_per_second:g} steps/s"
            line += f"   pace {self.achieved:.2f} × {asked} (the engine cannot keep up)"
        return line

    def advance(self, seconds: float, budget: float | None = None, early: bool = False) -> int:
        """Step for ``seconds`` of wall-clock time at the pace (at most ``budget`` s of
        stepping: a slow engine runs slower than real time rather than falling behind);
        stop with the diagnosis on a blow-up. ``early``: a step now even if none is due yet
        (the hand moved: `Grab` pins the particle at the next step), one step ahead of the
        pace at most, taken from the steps owed later. The number of steps done."""
        if budget is None:
            budget = BUDGET / self.send_rate
        asked = seconds * self.steps_per_second * self.speed
        self._owed += asked
        lent = 1.0 if early and 0.0 <= self._owed < 1.0 else 0.0
        self._owed += lent
        done, start = 0, time.perf_counter()
        try:
            while self._owed >= 1.0 and time.perf_counter() - start < budget:
                self.follow_hand()
                self.sim.step()
                self.trace.record(self.sim)
                self._owed -= 1.0
                done += 1
        except SimulationDiverged as error:
            self.running, self.error = False, str(error)
        self._owed = min(self._owed, 1.0) - lent  # what was not done in time is dropped
        self._asked += asked
        self._done += done
        return done

    def follow_hand(self) -> None:
        """Before a step: give `Grab` the hand's target at the step's time (`HandPath`,
        the wall-clock time of a step at the pace; paused, the newest); let go once the
        playback reached the move the hand let go at."""
        if self.hand is None:
            return
        if self._letting_go and self.hand.caught_up:
            self.let_go()
            return
        pace = self.steps_per_second * self.speed if self.running else 0.0
        self.grab.move(self.hand.advance(1000.0 / pace if pace > 0 else np.inf))

    def let_go(self) -> None:
        """The hand lets go of the held particle (it keeps the velocity of the last step)."""
        self.grab.release()
        self.hand, self._letting_go = None, False

    def do_pending(self) -> None:
        """Do what the page asked since the last call (grabs, slider moves, ...)."""
        while True:
            try:
                command = self._commands.get_nowait()
            except queue.Empty:
                return
            command()

    def frame(self, now: float | None = None) -> None:
        """One round of the stepping thread: the page's requests, steps, a frame sent.
        ``now``: the time (s, `time.perf_counter`) the frame stands for, by default now."""
        now = time.perf_counter() if now is None else now
        elapsed, self._clock = now - self._clock, now
        self._moved = False
        self.do_pending()
        if self.running and not self.error:
            self.advance(elapsed, early=self._moved)
        self._frames += 1
        self.publish(energy=self._frames % ENERGY_EVERY == 0 or not self.running)

    # ------------------------------------------------------------------ the page's requests
    def _on_message(self, _widget: object, content: dict, buffers: list) -> None:
        """A request from the page, queued for the stepping thread (or done now if none).
        A grab carries the time the hand was there (ms, the page's clock; without it, it is
        timed by its arrival), a move the hand's path since the last (``path``: ``[time,
        *target]`` each, `MOVES_EVERY` ms of it in live.js)."""
        stamp = float(content.get("time", 1000.0 * time.perf_counter()))
        handlers = {
            "grab": lambda: self._take(content["particle"], content["target"], stamp),
            "move": lambda: self._move(content["path"]),
            "release": self._release,
            "step": self.step_once,
            "reset": self.reset,
            "set": lambda: self.set(content["name"], content["value"]),
            "frames": lambda: self.match_frames(content["rate"]),
            "stopwatch": lambda: self.press_stopwatch(content["action"]),
            "export": lambda: self.send_export(content["format"]),
            "describe": self.describe,
            "pin": lambda: self.pin(content["particle"]),
        }
        command = handlers.get(content.get("type"))
        if command is not None:
            self._commands.put(command)
            if self._thread is None:
                self.do_pending()
            if content["type"] not in PACED:
                self._wake.set()  # a frame now: a grab, a step, a slider need not wait

    def _take(self, particle: int, target: list[float], stamp: float) -> None:
        """The hand takes ``particle`` at ``target`` at time ``stamp`` (ms)."""
        self.grab.hold(self.sim.body, particle, target)
        self.hand, self._letting_go = HandPath(stamp, target), False
        self.pick(particle)
        self._moved = True

    def _move(self, path: list[list[float]]) -> None:
        """The hand's moves, each ``[time, *target]`` (ms, world units), in the order made
        (nothing if it holds nothing)."""
        if self.hand is not None and not self._letting_go:
            for time_made, *target in path:
                self.hand.add(time_made, target)
            self._moved = True

    def _release(self) -> None:
        """Let go now if the playback has reached the hand (or the view is paused), else
        once it has (`follow_hand`)."""
        if self.hand is None or self.hand.caught_up or not self.running:
            self.let_go()
        else:
            self._letting_go = True

    def describe(self) -> None:
        """Send the whole state in words with the next state (`words.full`)."""
        self._describe = True

    def pin(self, particle: int) -> None:
        """Pin ``particle`` where it is, or free it if it is pinned. Pinned, it stops: the
        hand took its kinetic energy out (booked under "hand", as `Grab` books its work)."""
        body = self.sim.body
        if not 0 <= particle < len(body):
            raise ValueError(f"particle {particle} does not exist: the body has {len(body)}")
        if self.grab.particle == particle:
            self.let_go()
        if not body.fixed[particle]:
            speed = velocities_now(self.sim)[particle]
            self.sim.dissipated["hand"] += 0.5 * float(body.masses[particle] * speed @ speed)
            body.velocities[particle] = 0.0
        body.fixed[particle] = not body.fixed[particle]
        self.fixed = body.fixed.astype(np.uint8).tobytes()

    def match_frames(self, rate: float) -> None:
        """Send as many states a second as the page draws frames (``rate``, 1/s)."""
        self.send_rate = min(FRAME_RATE, max(SLOWEST, float(rate)))

    def step_once(self) -> None:
        """One step, paused or not."""
        self.running = False
        self._owed = 1.0
        self.advance(0.0)

    def reset(self) -> None:
        """Back to the positions and velocities at the start; the clock and ledger too."""
        self.let_go()
        x, v = self._initial
        self.sim.body.positions[...] = x
        self.sim.body.velocities[...] = v
        self.sim.time, self.sim.step_count = 0.0, 0
        self._taken = dict(self.sim.dissipated)
        self.error = ""
        self.set_up_instruments(keep_picks=True)

    def set(self, name: str, value: float) -> None:
        """Apply a slider: in place between steps, or by rebuilding the scene."""
        rebuild = {s["name"] for s in self.settings if s["rebuild"]}
        if name in rebuild and self.scene_entry is not None:
            self._values[name] = value
            built = {n: v for n, v in self._values.items() if n in rebuild}
            kinds = self.scene_entry.settings()
            built = {n: type(kinds[n])(v) for n, v in built.items()}
            self.attach(self.scene_entry.build(**built))
        else:
            settings.apply(self.sim, name, value, self._start)

    # ------------------------------------------------------------------ the instruments
    def set_up_instruments(self, keep_picks: bool = False) -> None:
        """A new run: the trace, the recording and the stopwatch start over; the trace
        follows the lowest free particle, the ruler runs from the first pinned one to it
        (``keep_picks``: the particles picked before)."""
        sim = self.sim
        self.stopwatch.stop()
        self.stopwatch.reset()
        units = (self.scene["time_unit"], self.scene["energy_unit"])
        self.recording = Recording(len(sim.body), sim.body.dim, *units)
        if keep_picks:
            self.follow(self.trace.particle)
            return
        traced = instruments.lowest_free(sim, self._up)
        pinned = np.flatnonzero(sim.body.fixed)
        start = int(pinned[0]) if len(pinned) else int(traced == 0)
        self.follow(traced)
        self.ruler_ends = (start, traced)
        self.presets = self.gravity_presets()

    def toggle(self, tool: str, on: bool | None = None) -> None:
        """Show the instrument ``tool`` (stopwatch, ruler, trace, lines, arrows) or hide
        it: ``on``, or the other way round from now."""
        if tool not in self.tools:
            raise ValueError(f"no instrument {tool!r}: choose one of {', '.join(self.tools)}")
        self.tools = {**self.tools, tool: not self.tools[tool] if on is None else bool(on)}

    def press_stopwatch(self, button: str) -> None:
        """The stopwatch's button ``button``: start, stop or reset."""
        watch = self.stopwatch
        actions = {"start": watch.start, "stop": watch.stop, "reset": watch.reset}
        if button not in actions:
            raise ValueError(f"the stopwatch has no button {button!r}: start, stop or reset")
        actions[button]()

    def gravity_presets(self) -> dict[str, float]:
        """|g| of Earth, Moon, Jupiter and zero in the scene's units: Earth's is 9.81 in
        SI, else the scene's own gravity at the start; none without gravity."""
        gravity = instruments.gravity_of(self.sim)
        if gravity is None:
            return {}
        if self._start["gravity"] is None:  # no direction yet: along the view's down
            self._start["gravity"] = -np.eye(self.sim.body.dim)[self._up]
        si = self.sim.units == SI
        earth = instruments.GRAVITY["Earth"] if si else float(np.linalg.norm(gravity.g))
        return instruments.GravityPresets(earth or instruments.GRAVITY["Earth"]).values()

    def set_gravity(self, preset: str) -> None:
        """Set gravity to a preset: "Earth", "Moon", "Jupiter" or "zero"."""
        if not self.presets:
            raise ValueError("this scene has no gravity to set: it was built without msd.Gravity")
        if preset not in self.presets:
            raise ValueError(
                f"no gravity preset {preset!r}: choose one of {', '.join(self.presets)}"
            )
        self.set("gravity", self.presets[preset])

    def follow(self, particle: int, axis: int | None = None) -> None:
        """Trace ``particle`` along ``axis`` (default: the vertical) from now on."""
        self.trace = instruments.Trace(particle, self._up if axis is None else axis)

    def pick(self, particle: int) -> None:
        """A particle taken in hand: the trace follows it, the ruler runs from the one
        picked before to it."""
        if particle != self.trace.particle:
            self.ruler_ends = (self.trace.particle, particle)
            self.follow(particle)

    def measure(self) -> dict:
        """What each instrument turned on in `tools` reads now, for the page."""
        sim, traced, on = self.sim, self.trace.particle, self.tools
        unit = self.recording.units["time"]
        readings: dict = {"time": sim.time}
        if on.get("stopwatch"):
            watch = self.stopwatch
            readings["stopwatch"] = {
                "reading": watch.reading,
                "running": watch.running,
                "unit": unit,
            }
        if on.get("ruler"):
            distance = instruments.distance(sim, self.ruler_ends)
            readings["ruler"] = {"ends": list(self.ruler_ends), "distance": distance}
        if on.get("trace"):
            period = self.trace.period()
            readings["trace"] = {
                "particle": traced,
                "axis": self.trace.axis,
                "points": self.trace.shown(),
                "period": period,
                "unit": unit,
            }
        if on.get("lines"):
            readings["lines"] = instruments.hanging_lines(sim, traced)
        if on.get("arrows"):
            readings["arrows"] = {"particle": traced, **instruments.arrows(sim, traced)}
        return readings

    def export(self, path: str | Path) -> Path:
        """Write the run shown to ``path``, a .csv table or a .npz of NumPy arrays: time,
        energies, positions and velocities of every state sent (the latest
        `export.RECORD_BYTES` of positions and velocities)."""
        return self.recording.write(path)

    def send_export(self, kind: str) -> None:
        """Send the page the run shown as a file to download (``kind``: csv or npz)."""
        data = self.recording.npz() if kind == "npz" else self.recording.csv()
        self.send({"type": "export", "name": f"msdlab-run.{kind}"}, [data])

    # ------------------------------------------------------------------ the thread
    def start(self) -> LiveView:
        """Start stepping in a background thread."""
        if self._thread is None:
            self._stop.clear()
            self._clock = time.perf_counter()
            self._thread = threading.Thread(target=self._loop, name="msdlab-live", daemon=True)
            self._thread.start()
        return self

    def stop(self) -> None:
        """Stop stepping (the page keeps drawing the last frame)."""
        self._stop.set()
        self._wake.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5)
        self._thread = None

    def _loop(self) -> None:
        """Send a state every 1/`send_rate` s on a fixed beat (a late one does not shift
        the next), and at once when the page asks something."""
        beat = time.perf_counter()
        while not self._stop.is_set():
            self._wake.clear()
            now = time.perf_counter()
            # a frame on the beat stands for the beat's time, not the wake-up's: at a pace
            # of one step a state, each frame then steps once, none twice and none never
            self.frame(min(now, beat))
            now = time.perf_counter()
            while beat <= now:  # the beats a slow frame overran are skipped, not caught up
                beat += 1.0 / self.send_rate
            self._wake.wait(beat - now)


def in_notebook() -> bool:
    """Whether this runs in a Jupyter kernel (where the widget shows)."""
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    return shell is not None and hasattr(shell, "kernel")


def live(sim: Simulation, **options) -> LiveView:
    """Start a `LiveView` of ``sim`` (stopping the one started before) and return it."""
    while _running:
        _running.pop().stop()
    widget = LiveView(sim, **options).start()
    _running.append(widget)
    return widget
