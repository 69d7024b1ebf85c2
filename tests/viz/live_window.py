"""A live view in a real Tk window, for test_live_window.py: writes where the mouse should
press and drag to ``work/aim.json``, and, once ``work/done`` appears, where the grabbed
particle ended to ``work/result.json``; then it closes the window."""

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("TkAgg")
import matplotlib.pyplot as plt

from msdlab import viz
from msdlab.scenes import gallery

PARTICLE, PULL = 37, (90.0, 60.0)  # px in the scene: right and up
work = Path(sys.argv[1])
dragger = viz.Dragger(gallery.mesh(gravity=0.0), steps_per_frame=2, interval=33)
canvas = dragger.ax.figure.canvas
widget = canvas.get_tk_widget()


def screen(point):
    """Screen pixels (X11, y down) of a point in the scene."""
    x, y = dragger.ax.transData.transform(point)
    return [widget.winfo_rootx() + x, widget.winfo_rooty() + widget.winfo_height() - y]


def publish(name: str, value: dict) -> None:
    """Write ``value`` to ``work/name`` whole: the test reads it as soon as it appears."""
    partial = work / (name + ".part")
    partial.write_text(json.dumps(value))
    partial.replace(work / name)


def aim():
    start = dragger.sim.body.positions[PARTICLE]
    aims = {"press": screen(start), "release": screen(start + PULL), "start": start.tolist()}
    publish("aim.json", aims)


def poll():
    if (work / "done").exists():
        held = dragger.grab.particle
        result = {
            "held": held,
            "position": dragger.sim.body.positions[PARTICLE].tolist(),
            "on_screen": screen(dragger.sim.body.positions[PARTICLE]),
        }
        publish("result.json", result)
        plt.close("all")


dragger.start()
canvas.new_timer(interval=1500, callbacks=[(aim, (), {})]).start()
poller = canvas.new_timer(interval=100, callbacks=[(poll, (), {})])
poller.start()
plt.show()
