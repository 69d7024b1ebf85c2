"""A recorded run as a self-contained HTML page drawn by the live view's front end.

The page holds the positions (float32, base64) and the body's springs, not
pictures, and the front end (``live.js``) itself: it plays, pauses, scrubs
and, in 3-D, orbits and zooms, with no network. The module is loaded from its
own text in the page (a blob: URL), so the page also works from file://.
"""

from __future__ import annotations

import base64
import json
from collections.abc import Sequence
from html import escape

import numpy as np

from ..simulation import Simulation, Trajectory
from . import frontend

PAGE = """<!DOCTYPE html>
<html lang="en">
<head><meta charset="utf-8"><title>{title}</title></head>
<body style="margin: 12px; font-family: sans-serif">
<h3 style="margin: 4px 0">{title}</h3>
<div id="msdlab-replay"></div>
<script type="text/plain" id="msdlab-module">{module}</script>
<script type="application/json" id="msdlab-data">{data}</script>
<script type="module">
const text = document.getElementById("msdlab-module").textContent;
const url = URL.createObjectURL(new Blob([text], {{ type: "text/javascript" }}));
const {{ replay }} = await import(url);
const data = JSON.parse(document.getElementById("msdlab-data").textContent);
replay(document.getElementById("msdlab-replay"), data);
</script>
</body>
</html>
"""


def _base64(array: np.ndarray | bytes) -> str:
    data = array if isinstance(array, bytes) else np.ascontiguousarray(array).tobytes()
    return base64.b64encode(data).decode("ascii")


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
    data = {
        "scene": scene,
        **{name: _base64(value) for name, value in frontend.body_arrays(body).items()},
        "frames": _base64(frames),
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
