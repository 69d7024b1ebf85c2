"""``msdlab demo``: drop the jelly cube on the floor, print its energy ledger, save an animation
and an energy plot (a few seconds, no window needed)."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from ..analysis import max_stable_dt
from ..scenes import get_scene
from .first_run import start_engine
from .progress import step_bar


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "demo",
        help="drop a jelly cube on the floor: energy ledger, animation and energy plot",
        description=__doc__,
    )
    parser.add_argument("--out", type=Path, default=Path("msdlab-output"), help="output folder")
    parser.add_argument("--size", type=int, default=6, help="particles per cube edge (brief: 20)")
    parser.add_argument("--steps", type=int, default=1200, help="time steps of dt = 0.4")
    parser.add_argument("--frames", type=int, default=24, help="frames in the animation")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """The brief's solved setting: k = 0.5, λ = 0.01, g = -0.001, dt = 0.4, 58.3° about z."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..viz import plot_energy, save_animation

    started = time.perf_counter()
    start_engine()
    scene = get_scene("jelly-cube")
    sim = scene.build(size=args.size)
    limit = max_stable_dt(sim.body, sim.integrator)
    print(f"jelly cube: {sim.body}, {sim.integrator!r}, dt = {sim.dt:g} (stable below {limit:.3g})")
    with step_bar(args.steps, "jelly cube") as bar:
        trajectory = sim.run(
            steps=args.steps,
            record_every=max(1, args.steps // 120),
            callback=lambda s: bar(s.step_count),
        )
    print(trajectory.energies.table(rows=8))
    args.out.mkdir(parents=True, exist_ok=True)
    animation = save_animation(
        trajectory,
        args.out / "demo.gif",
        max_frames=args.frames,
        fps=8,
        dpi=80,
        view=scene.view,
        up=scene.up,
        time_unit=scene.unit,
        energy_unit=scene.energy_unit,
        title="jelly cube",
    )
    energy_plot = args.out / "demo_energy.png"
    figure = plot_energy(
        trajectory.energies,
        time_unit=scene.unit,
        energy_unit=scene.energy_unit,
        save=energy_plot,
    )
    plt.close(figure)
    print(f"animation:   {animation.resolve()}")
    print(f"energy plot: {energy_plot.resolve()}")
    print(
        f"done in {time.perf_counter() - started:.1f} s. Next: `msdlab scenes`, "
        "`msdlab run trampoline --experiments`, `msdlab run cloth --save cloth.gif`."
    )
    return 0
