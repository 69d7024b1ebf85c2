"""A recorded run as a self-contained HTML page drawn by the live view's front end.

The page holds the positions (16-bit steps across the run's box, frame to frame
differences, deflated, in base64) and the body's springs, not pictures, and the
front end (``live.js``) itself: it plays, pauses, scrubs and, in 3-D, orbits and
zooms, with no network. The module is loaded from its
own text in the page (a blob: URL), so the page also works from file://.
"""

from __future__ import annotations

import base64
import json
import zlib
from collections.abc import Sequence
from html import escape

import numpy as np

from .. import Simulation, Trajectory
from . import frontend

PAGE = """<!DOCTYPE html>
<html lang="en">
<head><meta charset="utf-8"><title>{title}</title></head>
<body style="margin: 12px; font-family: sans-serif">
<main>
<h1 style="margin: 4px 0; font-size: 1.25em">{title}</h1>
<div id="msdlab-replay"></div>
</main>
<script type="text/plain" id="msdlab-module">{module}</script>
<script type="application/json" id="msdlab-data">{data}</script>
<script type="module">
const text = document.getElementById("msdlab-module").textContent;
const url = URL.createObjectURL(new Blob([text], {{ type: "text/javascript" }}));
const {{ replay }} = await import(url);
const data = JSON.parse(document.getElementById("msdlab-data").textContent);
await replay(document.getElementById("msdlab-replay"), data);
</script>
</body>
</html>
"""


def _packed(data: bytes) -> str:
    """``data`` deflated (zlib) and in base64: the page inflates it (DecompressionStream)."""
    return base64.b64encode(zlib.compress(data, 9)).decode("ascii")


def quantised(frames: np.ndarray) -> tuple[bytes, list[float], list[float]]:
    """Positions (F, N, d) as uint16 steps of (high - low) / 65535 per axis above ``low``,
    each frame as its difference from the one before (mod 2¹⁶: small numbers, which deflate
    well); the bytes, ``low`` and the step. A 20-unit cube is kept to 0.3 thousandths."""
    low, high = frames.min(axis=(0, 1)), frames.max(axis=(0, 1))
    step = np.where(high > low, (high - low) / 65535, 1.0)
    levels = np.round((frames - low) / step).astype(np.uint16)
    changes = np.concatenate([levels[:1], np.diff(levels, axis=0)])  # wraps mod 2¹⁶
    return changes.tobytes(), low.tolist(), step.tolist()


def replay_page(
    trajectory: Trajectory,
    picks: np.ndarray,
    *,
    fps: float,
    up: str,
    view: Sequence[float] | None,
    strain_limit: float,
    spheres: Sequence[tuple[int, float]] = (),
    time_unit: str = "s",
    title: str = "",
) -> str:
    """The page replaying frames ``picks`` of ``trajectory`` at ``fps`` frames a second."""
    body = trajectory.body.copy()
    frames = trajectory.positions[picks].astype(np.float32)
    body.positions[...] = trajectory.positions[picks[0]]
    scene = frontend.describe(
        Simulation(body),
        up=up,
        view=view,
        strain_limit=strain_limit,
        spheres=spheres,
        energy=False,
    )
    scene["span"] = float(np.max(np.ptp(frames.reshape(-1, body.dim), axis=0))) * 1.1 or 1.0
    scene["centre"] = (0.5 * (frames.min(axis=(0, 1)) + frames.max(axis=(0, 1)))).tolist()
    changes, low, step = quantised(frames)
    data = {
        "scene": scene,
        **{name: _packed(value) for name, value in frontend.body_arrays(body).items()},
        "frames": _packed(changes),
        "low": low,
        "step": step,
        "times": trajectory.times[picks].tolist(),
        "fps": fps,
        "unit": time_unit,
    }
    module = frontend.ESM.read_text("utf-8")
    if "</" in module:
        raise ValueError("live.js must not contain '</': it is embedded in a <script>")
    return PAGE.format(
        title=escape(title or "msdlab replay"),
        module=module,
        data=json.dumps(data).replace("</", "<\\/"),
    )
