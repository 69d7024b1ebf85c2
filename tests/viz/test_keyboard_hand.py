"""The keyboard's hand: a drag by arrow keys books the same work as a pointer's drag of the
same path, and a pinned particle's kinetic energy is booked as taken out by the hand."""

import numpy as np
import pytest

from msdlab.scenes import gallery
from msdlab.viz.widget import LiveView, energies

FRAME = 1000 / 60  # ms: a frame of the page, a step of the gallery's mesh
KEY_EVERY = 50.0  # ms between two key presses of a held arrow key
STEP = 4.0  # px a key press moves the hand
GLIDE = 50.0  # ms a key's move takes at most (live.js)


def books(view: LiveView) -> tuple[float, float]:
    """The energy in the body plus all taken out, and the work the hand put in so far."""
    e = energies(view.sim, {})
    in_body = e["kinetic"] + e["elastic"] + e["gravitational"] + e["other"]
    return in_body + sum(e["dissipated"].values()), -e["dissipated"].get("hand", 0.0)


def corners(start: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """The held arrow keys' path: (time in ms, target) of each press, 15 presses right then
    15 up, from 500 ms on."""
    moves = [(1.0, 0.0)] * 15 + [(0.0, -1.0)] * 15
    points, at = [], start.copy()
    for k, move in enumerate(moves):
        at = at + STEP * np.array(move)
        points.append((500.0 + KEY_EVERY * k, at))
    return points


def keyboard(start: np.ndarray) -> list[tuple[float, dict]]:
    """The page's messages for the keys (live.js): the grab (Enter) at once, each key's move
    from where the hand stood (at the last move, or `GLIDE` before) to the new target."""
    messages = [(0.0, {"type": "grab", "time": 0.0, "target": start.tolist()})]
    last, at = 0.0, start
    for time, target in corners(start):
        since = max(time - GLIDE, last)
        path = [[since, *at], [time, *target]]
        messages.append((time, {"type": "move", "path": path}))
        last, at = time, target
    return [*messages, (last + 1, {"type": "release"})]


def pointer(start: np.ndarray) -> list[tuple[float, dict]]:
    """A mouse along the same path: taken where the keys' first move starts, a move each
    frame (on the path's straight lines between the keys' targets)."""
    times, targets = zip(*[(450.0, start), *corners(start)])
    grab = {"type": "grab", "time": 450.0, "target": start.tolist()}
    messages = [(450.0, grab)]
    for time in np.arange(450.0 + FRAME, times[-1] + FRAME, FRAME):
        time = min(time, times[-1])
        target = [np.interp(time, times, [t[k] for t in targets]) for k in (0, 1)]
        messages.append((time, {"type": "move", "path": [[time, *target]]}))
    return [*messages, (times[-1] + 1, {"type": "release"})]


def drag(messages: list[tuple[float, dict]]) -> tuple[float, float]:
    """The change of the books (total, hand's work) over a drag of the mesh without
    gravity by the page's ``messages`` (each at its time, ms), and a second after it."""
    view = LiveView(gallery.mesh(gravity=0.0), steps_per_second=60)
    view._thread = True  # the page's requests wait for the next frame, as they do running
    x = view.sim.body.positions
    particle = int(np.argmax(x[:, 0] - x[:, 1]))
    before, now, queue = books(view), view._clock, list(messages)
    for frame in range(300):
        while queue and queue[0][0] <= frame * FRAME:
            view._on_message(view, {**queue.pop(0)[1], "particle": particle}, [])
        view.frame(now := now + 1 / 60)
    assert view.grab.particle is None and not queue
    return tuple(np.subtract(books(view), before))


def test_a_keyboard_drag_books_the_work_of_a_pointer_drag_of_the_same_path():
    start = gallery.mesh(gravity=0.0).body.positions
    start = start[int(np.argmax(start[:, 0] - start[:, 1]))].copy()
    keys_total, keys_work = drag(keyboard(start))
    _, mouse_work = drag(pointer(start))
    assert mouse_work > 100.0
    assert keys_work == pytest.approx(mouse_work, rel=0.01)
    assert abs(keys_total) < 0.015 * keys_work  # the books balance (0.9 %)


def test_pinning_a_moving_particle_books_its_kinetic_energy_under_the_hand():
    view = LiveView(gallery.mesh(), steps_per_second=60)
    for _ in range(40):
        view.advance(1 / 60)
    before = books(view)[0]
    fastest = int(np.argmax(np.linalg.norm(view.sim.body.velocities, axis=1)))
    view._on_message(view, {"type": "pin", "particle": fastest}, [])
    assert view.sim.body.fixed[fastest]
    assert np.frombuffer(view.fixed, np.uint8)[fastest] == 1  # the page draws it pinned
    assert books(view)[1] < 0  # taken out, not put in
    assert books(view)[0] == pytest.approx(before, rel=1e-9)
    at = view.sim.body.positions[fastest].copy()
    for _ in range(30):
        view.advance(1 / 60)
    np.testing.assert_array_equal(view.sim.body.positions[fastest], at)
    view._on_message(view, {"type": "pin", "particle": fastest}, [])
    assert not view.sim.body.fixed[fastest]
