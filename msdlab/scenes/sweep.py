"""Parameter sweeps: run a scene for every combination of settings, one table of outcomes.

``--sweep stiffness=0.25,1,4 --sweep dt=0.5,1,2`` runs 3 × 3 simulations. Each
row holds the combination and what came out of it: whether it blew up, the
steps and time reached, the integrator's relative energy drift (energy it
created or lost on its own, over the run's energy scale) and the largest
displacement of any particle from its start. Each simulation is independent,
so a Dask cluster can run them side by side (`run_point` is what it runs).
"""

from __future__ import annotations

import ast
import csv
import itertools
import math
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from .. import Integrator, SimulationDiverged, Trajectory
from ..analysis.cluster import run_all
from .registry import Scene, get_scene

RUN_SETTINGS = ("dt", "integrator", "duration")  # swept like the scene's own settings
OUTCOMES = ("diverged", "steps", "time", "energy_drift", "max_displacement")


def parse_sweeps(scene: Scene, items: Sequence[str]) -> dict[str, list[object]]:
    """``key=v1,v2,...`` strings as {key: values}, values read as Python literals (or words)."""
    valid = [*scene.settings(), *RUN_SETTINGS]
    axes: dict[str, list[object]] = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not text.strip():
            raise ValueError(f"--sweep takes key=v1,v2,..., got {item!r}")
        if key not in valid:
            raise ValueError(
                f"scene {scene.name!r} has no setting {key!r} to sweep; valid: {', '.join(valid)}"
            )
        if key in axes:
            raise ValueError(f"--sweep {key} is given twice; list all its values in one")
        axes[key] = [_literal(value) for value in text.split(",")]
    return axes


def combinations(axes: dict[str, list[object]]) -> list[dict[str, object]]:
    """Every combination of the axes' values, the last axis varying fastest."""
    return [dict(zip(axes, values)) for values in itertools.product(*axes.values())]


def run_point(
    scene_name: str,
    settings: dict[str, object],
    *,
    duration: float,
    dt: float | None = None,
    integrator: type[Integrator] | None = None,
) -> dict[str, object]:
    """Run one combination for ``duration`` (the scene's time unit) and measure its outcomes."""
    sim = get_scene(scene_name).build(**settings)
    if integrator is not None:
        sim.integrator = integrator()
    if dt is not None:
        sim.dt = dt
    steps = round(duration / sim.dt)
    try:
        trajectory = sim.run(steps=steps, record_every=max(1, steps // 500))
        diverged = False
    except SimulationDiverged as error:
        trajectory, diverged = error.trajectory, True
    return {"diverged": diverged, **_measures(trajectory, sim.step_count, sim.time)}


def sweep(
    scene: Scene,
    axes: dict[str, list[object]],
    *,
    fixed: dict[str, object],
    duration: float,
    dt: float | None = None,
    integrators: dict[str, type[Integrator]],
    integrator: str | None = None,
    cluster: str | None = None,
    progress: Callable[[int], None] | None = None,
) -> list[dict[str, object]]:
    """One row per combination of ``axes`` (on top of the ``fixed`` settings): the combination
    and its outcomes; here, calling ``progress(done)`` after each, or on the workers of
    ``cluster`` (``local:N`` or a Dask scheduler's address: `analysis.cluster.run_all`)."""
    rows = combinations(axes)
    calls = []
    for row in rows:
        settings = {**fixed, **{k: v for k, v in row.items() if k not in RUN_SETTINGS}}
        name = row.get("integrator", integrator)
        if name is not None and name not in integrators:
            raise ValueError(f"unknown integrator {name!r}; choose one of {', '.join(integrators)}")
        options = {
            "duration": float(row.get("duration", duration)),
            "dt": row.get("dt", dt),
            "integrator": integrators[name] if name is not None else None,
        }
        calls.append((settings, options))
    if cluster is None:
        outcomes = []
        for done, (settings, options) in enumerate(calls, start=1):
            outcomes.append(run_point(scene.name, settings, **options))
            if progress is not None:
                progress(done)
    else:
        jobs = [((scene.name, settings), options) for settings, options in calls]
        outcomes = run_all(cluster, run_point, jobs, label="sweep")
        for row, outcome in zip(rows, outcomes):
            if isinstance(outcome, BaseException):
                raise RuntimeError(f"the sweep's run {row} failed: {outcome!r}") from outcome
    return [{**row, **outcome} for row, outcome in zip(rows, outcomes)]


def write_table(rows: Sequence[dict[str, object]], path: Path) -> None:
    """The rows as CSV: the swept settings, then the outcomes."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def format_table(rows: Sequence[dict[str, object]]) -> str:
    """The rows as aligned text, numbers to 4 significant digits."""
    columns = list(rows[0])
    cells = [[_cell(row[c]) for c in columns] for row in rows]
    widths = [max(len(c), *(len(r[i]) for r in cells)) for i, c in enumerate(columns)]
    lines = ["  ".join(c.rjust(w) for c, w in zip(columns, widths))]
    lines += ["  ".join(v.rjust(w) for v, w in zip(r, widths)) for r in cells]
    return "\n".join(lines)


def _measures(trajectory: Trajectory | None, steps: int, time: float) -> dict[str, object]:
    """Steps and time reached, relative energy drift, largest displacement (of the frames
    recorded before a blow-up, if there was one)."""
    if trajectory is None or len(trajectory) == 0:
        return {
            "steps": steps,
            "time": time,
            "energy_drift": math.nan,
            "max_displacement": math.nan,
        }
    moved = np.linalg.norm(trajectory.positions - trajectory.positions[0], axis=-1)
    return {
        "steps": steps,
        "time": time,
        "energy_drift": trajectory.energies.relative_drift(),
        "max_displacement": float(np.max(moved)),
    }


def _literal(text: str) -> object:
    try:
        return ast.literal_eval(text.strip())
    except (ValueError, SyntaxError):
        return text.strip()  # a word, e.g. model=frame


def _cell(value: object) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)
