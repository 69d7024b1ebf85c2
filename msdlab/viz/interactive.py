"""Grab a particle with the mouse and drag it while the simulation runs (2-D and 3-D).

Works in any interactive matplotlib window and in Jupyter with ipympl
(``%matplotlib widget``). Press the left button near a particle to take the
nearest one in hand (`Grab`), move to drag it, release to let go: it keeps the
hand's velocity, not the spring forces it resisted. In 3-D the particle moves
parallel to the screen; the right button turns the view.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from time import perf_counter
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backend_bases import MouseEvent
from matplotlib.patches import Rectangle

from .. import Simulation, SimulationDiverged
from ..interaction import Grab, Walls
from .upright import resolve_up
from .view import LIVE_STRAIN_LIMIT, BodyView, new_axes, spheres_of

if TYPE_CHECKING:
    from .widget import LiveView

CATCH_UP = 0.25  # s of simulation a paced live view may step in one frame after a slow one
INSTRUCTIONS_2D = "drag a particle with the left mouse button · close the window (or q) to quit"
INSTRUCTIONS_3D = "left button: drag a particle · right button: turn · q or close: quit"
_running: list[Dragger] = []  # live views started by `show`, stopped when a new one starts


class Dragger:
    """Runs ``sim`` in a figure with mouse grabbing: ``steps_per_frame`` steps per ``interval`` ms.

    With ``steps_per_second`` the simulation keeps that pace instead, however
    long a frame takes to draw: each frame steps as often as the time since
    the last one asks (a full matplotlib redraw took about 70 ms here, so a fixed
    number of steps per frame would run slower than the page's 60 a second).
    `advance` does one frame (the timer calls it; tests call it directly). The
    axes hold the whole box of the scene's `Walls` when it has them.
    """

    def __init__(
        self,
        sim: Simulation,
        ax: Axes | None = None,
        *,
        steps_per_frame: int = 1,
        steps_per_second: float | None = None,
        interval: int = 30,
        view: Sequence[float] | None = None,
        up: str | None = None,
    ) -> None:
        self.sim = sim
        self.steps_per_frame = int(steps_per_frame)
        self.steps_per_second = steps_per_second
        self._due_since: float | None = None  # time from which steps are owed (s)
        self.grab = Grab()
        sim.constraints.append(self.grab)
        self.ax = ax or new_axes(sim.body, layout="none")  # the mouse needs still axes
        self.drawing = BodyView(
            self.ax,
            sim.body,
            strain_limit=LIVE_STRAIN_LIMIT,
            view=view,
            up=resolve_up(up, sim, sim.body.dim),
            spheres=spheres_of(sim),
        )
        self._show_box()
        self.ax.set_title(INSTRUCTIONS_3D if self.drawing.is_3d else INSTRUCTIONS_2D, fontsize=9)
        self._press: tuple[np.ndarray, np.ndarray] | None = None  # (screen px, target) at press
        if self.drawing.is_3d:
            self.ax.mouse_init(rotate_btn=3, pan_btn=2, zoom_btn=[])
        canvas = self.ax.figure.canvas
        self._connections = [
            canvas.mpl_connect("button_press_event", self.on_press),
            canvas.mpl_connect("motion_notify_event", self.on_motion),
            canvas.mpl_connect("button_release_event", self.on_release),
        ]
        self.timer = canvas.new_timer(interval=interval)
        self.timer.add_callback(self.advance)

    def start(self) -> Dragger:
        """Start stepping on the figure's timer."""
        self.timer.start()
        return self

    def stop(self) -> None:
        """Stop stepping and stop listening to the mouse (the figure stays as it is)."""
        self.timer.stop()
        self.timer.remove_callback(self.advance)
        for connection in self._connections:
            self.ax.figure.canvas.mpl_disconnect(connection)
        self._connections = []

    def _show_box(self) -> None:
        """Fit the axes to the walls (drawn as a frame) so the floor and sides are in view."""
        walls = [c for c in (*self.sim.forces, *self.sim.constraints) if isinstance(c, Walls)]
        if not walls or self.drawing.is_3d:
            return
        lower, upper = walls[0].lower, walls[0].upper
        margin = 0.03 * float(np.max(upper - lower))
        self.ax.set(
            xlim=(lower[0] - margin, upper[0] + margin),
            ylim=(lower[1] - margin, upper[1] + margin),
        )
        box = Rectangle(lower, *(upper - lower), fill=False, color="0.3", linewidth=2.0)
        self.ax.add_patch(box)

    def advance(self) -> None:
        """Step the simulation one frame and redraw; on a blow-up, stop and say why."""
        try:
            for _ in range(self._steps_due()):
                self.sim.step()
        except SimulationDiverged as error:
            self.timer.stop()
            self.ax.set_title(textwrap.fill(f"stopped: {error}", 90), fontsize="small")
        self.drawing.update(self.sim.body.positions)
        self.ax.figure.canvas.draw_idle()

    def _steps_due(self) -> int:
        """Steps for this frame: ``steps_per_frame``, or the steps the time since the last
        frame asks at ``steps_per_second`` (at most `CATCH_UP` seconds' worth: a frame
        that hung does not leave a backlog)."""
        if self.steps_per_second is None:
            return self.steps_per_frame
        now = perf_counter()
        if self._due_since is None:
            self._due_since = now - 1.0 / self.steps_per_second  # the first frame: one step
        due = int((now - self._due_since) * self.steps_per_second + 1e-9)  # 0.99999... is 1
        most = max(1, int(CATCH_UP * self.steps_per_second))
        if due > most:
            self._due_since, due = now, most
        else:
            self._due_since += due / self.steps_per_second
        return due

    # ------------------------------------------------------------------ mouse
    def on_press(self, event: MouseEvent) -> None:
        if event.inaxes is not self.ax or event.button != 1:
            return
        mouse = np.array([event.x, event.y], dtype=float)
        screen = self._to_screen(self.sim.body.positions)
        nearest = int(np.argmin(np.linalg.norm(screen - mouse, axis=1)))
        self.grab.hold(self.sim.body, nearest)
        self._press = (mouse, self.sim.body.positions[nearest].copy())
        self.on_motion(event)

    def on_motion(self, event: MouseEvent) -> None:
        if self._press is None or event.x is None or event.y is None:
            return
        mouse, start = self._press
        if not self.drawing.is_3d:
            inverse = self.ax.transData.inverted()
            self.grab.move(inverse.transform((event.x, event.y)))
            return
        wanted = self._to_screen(start[None])[0] + (event.x, event.y) - mouse
        target = start.copy()
        for _ in range(3):  # Newton steps on screen(target) = wanted, moving parallel to the screen
            miss = wanted - self._to_screen(target[None])[0]
            target += np.linalg.pinv(self._screen_jacobian(target)) @ miss
        self.grab.move(target)

    def on_release(self, event: MouseEvent) -> None:
        if self._press is not None:
            self.grab.release()
            self._press = None

    # ------------------------------------------------------------------ geometry
    def _to_screen(self, points: np.ndarray) -> np.ndarray:
        """Screen pixels (M, 2) of points (M, d)."""
        if not self.drawing.is_3d:
            return self.ax.transData.transform(points)
        from mpl_toolkits.mplot3d import proj3d

        x, y, _ = proj3d.proj_transform(*points.T, self.ax.get_proj())
        return self.ax.transData.transform(np.column_stack([x, y]))

    def _screen_jacobian(self, point: np.ndarray) -> np.ndarray:
        """d(screen px)/d(position) at ``point``, by finite differences, (2, 3)."""
        span = np.ptp(np.array([self.ax.get_xlim(), self.ax.get_ylim(), self.ax.get_zlim()]), 1)
        step = 1e-4 * span
        probes = point + np.vstack([np.zeros(3), np.diag(step)])
        screen = self._to_screen(probes)
        return ((screen[1:] - screen[0]) / step[:, None]).T


def check_display() -> None:
    """Raise RuntimeError if matplotlib cannot open a window (no display, Agg backend)."""
    import matplotlib
    import matplotlib.pyplot as plt  # noqa: F401  (selects the backend)

    if matplotlib.get_backend().lower() == "agg":
        raise RuntimeError(
            "no display: showing a window needs an interactive matplotlib backend "
            "(a desktop session, or %matplotlib widget in Jupyter); save an animation instead"
        )


def show(sim: Simulation, **options) -> Dragger | LiveView:
    """Run ``sim`` live with mouse dragging: in a notebook as a `widget.LiveView` (the
    browser draws), elsewhere in a matplotlib window (blocks until it is closed). A live
    view started earlier by `show` is stopped first, so re-running a notebook cell leaves
    one simulation running. ``options``: ``view``, ``up``, ``steps_per_second``."""
    from .widget import in_notebook, live

    if in_notebook():
        from IPython.display import display

        paced = {k: v for k, v in options.items() if k in ("view", "up", "steps_per_second")}
        widget = live(sim, **paced)
        display(widget)
        return widget
    import matplotlib.pyplot as plt

    check_display()
    while _running:
        _running.pop().stop()
    dragger = Dragger(sim, **options).start()
    _running.append(dragger)
    manager = dragger.ax.figure.canvas.manager
    if manager is not None:
        manager.set_window_title("msdlab: live view")
    plt.show()
    return dragger
