"""``msdlab run SCENE``: run a scene, print its energy ledger, save or show an animation.

With ``--sweep key=v1,v2,...`` (repeatable) it runs every combination of the values
instead and writes one table of outcomes (--out), on a Dask cluster with --cluster.
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

from .. import Simulation, SimulationDiverged, Trajectory
from ..engine import integrators
from ..scenes import SCENES, Scene, get_scene, sweep
from ..scenes.trampoline import EXPERIMENTS, experiment_table, run_experiment
from .first_run import start_engine
from .progress import count_bar, step_bar

INTEGRATORS: dict[str, type[integrators.Integrator]] = {
    "explicit-euler": integrators.ExplicitEuler,
    "symplectic-euler": integrators.SymplecticEuler,
    "verlet": integrators.Verlet,
    "velocity-verlet": integrators.VelocityVerlet,
    "rk4": integrators.RK4,
    "implicit-euler": integrators.ImplicitEuler,
}


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "run",
        help="run a scene: energy ledger, animation (--save), live window (--show)",
        description=__doc__ + " `msdlab scenes` lists the scenes, `msdlab scenes NAME` "
        "their settings.",
    )
    parser.add_argument("scene", choices=list(SCENES), metavar="SCENE", help="a scene name")
    parser.add_argument("--duration", type=float, help="how long to run (default: the scene's)")
    parser.add_argument("--dt", type=float, help="time step (default: the scene's)")
    parser.add_argument(
        "--integrator", choices=list(INTEGRATORS), help="replace the scene's integrator"
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="change a scene setting, e.g. --set ball_mass=5 (repeatable)",
    )
    parser.add_argument(
        "--save", type=Path, metavar="FILE", help="write an animation: FILE.gif, .mp4 or .html"
    )
    parser.add_argument(
        "--show", action="store_true", help="open a window; drag particles with the mouse"
    )
    parser.add_argument(
        "--experiments",
        action="store_true",
        help="trampoline only: run the report's seven experiments and print their outcomes",
    )
    parser.add_argument(
        "--sweep",
        action="append",
        default=[],
        metavar="KEY=V1,V2,...",
        help="run every combination of these values of a setting (or dt, integrator, duration)"
        " and write one table of outcomes (repeatable)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        metavar="FILE.csv",
        help="the sweep's table (default: msdlab-output/SCENE-sweep.csv)",
    )
    parser.add_argument(
        "--cluster",
        metavar="ADDRESS|local:N",
        help="run the sweep on a Dask scheduler or N local worker processes (msdlab[cluster])",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    scene = get_scene(args.scene)
    settings = parse_settings(scene, args.set)
    if args.sweep and (args.save or args.show or args.experiments):
        raise ValueError(
            "--sweep writes a table; run one setting for --save, --show, --experiments"
        )
    if args.save is not None:
        from ..viz.animation import check_format

        check_format(args.save)
    if args.show:
        from ..viz.interactive import check_display

        check_display()
    start_engine()
    if args.experiments:
        return _experiments(scene, settings, args)
    if args.sweep:
        return _sweep(scene, settings, args)
    if args.cluster or args.out:
        raise ValueError("--cluster and --out go with --sweep KEY=V1,V2,...")
    if args.show and args.save is None:  # the live view at once, no run before it
        from ..viz import show

        show(_build(scene, settings, args), view=scene.view, up=scene.up, **_live_pace(scene))
        return 0
    sim = _build(scene, settings, args)
    steps = round((args.duration or scene.duration) / sim.dt)
    print(f"{scene.name}: {sim!r}")
    trajectory = _run(sim, steps, scene.name)
    if trajectory is None:
        return 1
    print(trajectory.energies.table(rows=10))
    if args.save is not None:
        from ..viz import save_scene_animation

        path = save_scene_animation(scene, sim, trajectory, args.save)
        print(f"animation written to {path.resolve()}")
    if args.show:
        from ..viz import show

        show(_build(scene, settings, args), view=scene.view, up=scene.up, **_live_pace(scene))
    return 0


def _live_pace(scene: Scene) -> dict[str, float]:
    """The pace of the live view: the gallery's page steps 60 times a second (one step a
    frame), kept whatever the drawing costs; the other scenes show a step per 30 ms frame."""
    if scene.unit == "frames":
        return {"steps_per_second": 60.0, "interval": 33}
    return {"steps_per_frame": 1, "interval": 30}


def parse_settings(scene: Scene, items: list[str]) -> dict[str, object]:
    """``key=value`` strings as keyword arguments of the scene (values read as Python literals)."""
    valid = scene.settings()
    valid.pop("integrator", None)
    settings = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep:
            raise ValueError(f"--set takes key=value, got {item!r}")
        if key not in valid:
            raise ValueError(
                f"scene {scene.name!r} has no setting {key!r}; valid settings: {', '.join(valid)}"
            )
        try:
            settings[key] = ast.literal_eval(text.strip())
        except (ValueError, SyntaxError):
            settings[key] = text.strip()  # a word, e.g. model=frame
    return settings


def _build(scene: Scene, settings: dict[str, object], args: argparse.Namespace) -> Simulation:
    sim = scene.build(**settings)
    if args.integrator is not None:
        sim.integrator = INTEGRATORS[args.integrator]()
    if args.dt is not None:
        sim.dt = args.dt
    return sim


def _run(sim: Simulation, steps: int, label: str) -> Trajectory | None:
    """Run with a progress bar; on a blow-up print the diagnosis and return None."""
    try:
        with step_bar(steps, label) as bar:
            return sim.run(
                steps=steps,
                record_every=max(1, steps // 200),
                callback=lambda s: bar(s.step_count),
            )
    except SimulationDiverged as error:
        print(f"the simulation blew up: {error}")
        return None


def _experiments(scene: Scene, settings: dict[str, object], args: argparse.Namespace) -> int:
    if scene.name != "trampoline":
        raise ValueError(
            "--experiments runs the trampoline report's experiments: msdlab run "
            "trampoline --experiments"
        )
    duration = args.duration or scene.duration
    if args.dt is not None:
        settings["dt"] = args.dt
    if args.integrator is not None:
        settings["integrator"] = INTEGRATORS[args.integrator]()
    with count_bar(len(EXPERIMENTS), "experiments") as bar:
        outcomes = []
        for experiment in EXPERIMENTS.values():
            outcomes.append(run_experiment(experiment, duration, **settings))
            bar.update()
    print(f"ball centre heights in m after {duration:g} s (deepest, mean of the last second):")
    print(experiment_table(outcomes))
    return 0


def _sweep(scene: Scene, settings: dict[str, object], args: argparse.Namespace) -> int:
    axes = sweep.parse_sweeps(scene, args.sweep)
    out = args.out or Path("msdlab-output") / f"{scene.name}-sweep.csv"
    count = len(sweep.combinations(axes))
    options = dict(fixed=settings, duration=args.duration or scene.duration, dt=args.dt,
                   integrators=INTEGRATORS, integrator=args.integrator)  # fmt: skip
    print(f"{scene.name}: sweeping {' × '.join(axes)}, {count} runs")
    if args.cluster:
        rows = sweep.sweep(scene, axes, cluster=args.cluster, **options)
    else:
        with count_bar(count, "sweep") as bar:
            rows = sweep.sweep(
                scene, axes, progress=lambda done: bar.update(done - bar.n), **options
            )
    sweep.write_table(rows, out)
    print(sweep.format_table(rows))
    print(f"table written to {out}")
    return 0
