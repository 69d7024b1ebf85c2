"""The sliders of a live view: settings of a running simulation, applied between steps.

Stiffness, damping, gravity and dt change the simulation in place (the
stiffness slider scales every spring by the same factor, shown as the mean k).
A scene's own build settings (`Scene.settings`: grid size, pull, ...) need the
scene built again: their sliders say so and a change rebuilds it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .. import Gravity, Simulation, ViscousDamping
from ..interaction import Drag
from ..scenes.registry import Scene


@dataclass
class Setting:
    """A slider: ``name``, shown as ``label``, from ``low`` to ``high`` in steps of ``step``."""

    name: str
    label: str
    value: float
    low: float
    high: float
    step: float
    rebuild: bool = False

    def as_dict(self) -> dict:
        """For the front end (JSON): min, max, step, value, label, rebuild."""
        fields = asdict(self)
        fields["min"], fields["max"] = fields.pop("low"), fields.pop("high")
        return fields


def _slider(name: str, label: str, value: float, low: float, high: float) -> Setting:
    return Setting(name, label, float(value), float(low), float(high), (high - low) / 200)


def _damper(sim: Simulation) -> tuple[object, str] | None:
    """The object and attribute holding the simulation's damping, if it has one."""
    for item in (*sim.constraints, *sim.forces):
        if isinstance(item, Drag):
            return item, "rate"
        if isinstance(item, ViscousDamping):
            return item, "coefficient"
    if hasattr(sim.integrator, "damping"):
        return sim.integrator, "damping"
    return None


def _gravity(sim: Simulation) -> Gravity | None:
    return next((f for f in sim.forces if isinstance(f, Gravity)), None)


def live_settings(sim: Simulation) -> list[Setting]:
    """Sliders for what ``sim`` lets change while it runs."""
    settings = []
    if sim.body.n_springs:
        k = float(np.mean(sim.body.spring_set.stiffness))
        settings.append(_slider("stiffness", "stiffness k", k, k / 10, 4 * k))
    damper = _damper(sim)
    if damper is not None:
        owner, attribute = damper
        value = float(getattr(owner, attribute))
        high = max(0.9, value) if attribute == "damping" else max(4 * value, 1e-3)
        settings.append(_slider("damping", f"damping ({attribute})", value, 0.0, high))
    gravity = _gravity(sim)
    if gravity is not None:
        g = float(np.linalg.norm(gravity.g))
        settings.append(_slider("gravity", "gravity |g|", g, 0.0, max(3 * g, 1e-3)))
    settings.append(_slider("dt", "dt", sim.dt, sim.dt / 10, 3 * sim.dt))
    return settings


def scene_settings(scene: Scene, taken: set[str]) -> list[Setting]:
    """Sliders for the numeric build settings of ``scene`` not in ``taken``; they rebuild."""
    settings = []
    for name, default in scene.settings().items():
        if name in taken or isinstance(default, bool) or not isinstance(default, (int, float)):
            continue
        low, high = (0.0, 1.0) if default == 0 else sorted((default / 4, default * 4))
        setting = _slider(name, f"{name} (rebuilds)", default, low, high)
        if isinstance(default, int):
            setting.low, setting.high, setting.step = max(1, default // 4), 4 * default, 1
        setting.rebuild = True
        settings.append(setting)
    return settings


def apply(sim: Simulation, name: str, value: float, start: dict[str, object]) -> None:
    """Set the live setting ``name`` of ``sim`` to ``value``; ``start`` holds the stiffness
    and gravity direction at the start ("stiffness", "gravity")."""
    if name == "stiffness":
        scaled = np.asarray(start["stiffness"]) * (value / float(np.mean(start["stiffness"])))
        sim.body.set_springs(stiffness=scaled[0] if np.all(scaled == scaled[0]) else scaled)
    elif name == "damping":
        owner, attribute = _damper(sim)  # type: ignore[misc]
        setattr(owner, attribute, float(value))
    elif name == "gravity":
        _gravity(sim).g = np.asarray(start["gravity"]) * float(value)  # type: ignore[union-attr]
    elif name == "dt":
        sim.dt = float(value)
    else:
        raise ValueError(f"no live setting {name!r}")


def start_of(sim: Simulation) -> dict[str, object]:
    """What `apply` scales: the springs' stiffness and gravity's direction at the start."""
    gravity = _gravity(sim)
    direction = None
    if gravity is not None and np.any(gravity.g):
        direction = gravity.g / np.linalg.norm(gravity.g)
    return {"stiffness": sim.body.spring_set.stiffness.copy(), "gravity": direction}
