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
    print(
        f"jelly cube: {sim.body}, {sim.integrator!r}, dt = {sim.dt:g} {scene.unit} (the "
        f"engine predicts this integrator stable below dt = {limit:.3g} {scene.unit})"
    )
    with step_bar(args.steps, "jelly cube") as bar:
        trajectory = sim.run(
            steps=args.steps,
            record_every=max(1, args.steps // 120),
            callback=lambda s: bar(s.step_count),
        )
    print(trajectory.energies.table(rows=8))
    print(legend(trajectory.energies.dissipated, scene.unit, scene.energy_unit))
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


COLUMNS = {
    "time": "time simulated so far",
    "kinetic": "½ m v², summed over the particles",
    "elastic": "½ k (|x_i - x_j| - l)², summed over the springs",
    "potential": "-m g·x, the gravitational energy (0 at the floor y = 0)",
    "total": "kinetic + elastic + potential: the energy in the body",
    "drift": "the integrator's own error, total + all taken out - total at the start (ideally 0)",
}
TAKEN_OUT = {
    "dashpot": "the springs' dashpots",
    "integrator": "the integrator's damping λ",
    "ground": "the floor (contact and friction)",
    "viscous": "viscous damping, the force -c v on every particle",
    "drag": "air drag, v slowed by exp(-rate dt) each step",
    "hand": "the hand holding a particle (what it puts in counts negative)",
    "walls": "the walls",
    "driven": "a driven particle",
}


def legend(taken_out: dict, time_unit: str, energy_unit: str) -> str:
    """What the ledger's columns are, with their units: the energies in the body, what each
    mechanism in ``taken_out`` took out so far, and the drift."""
    rows = [(name, COLUMNS[name]) for name in ("time", "kinetic", "elastic", "potential", "total")]
    rows += [
        (name, f"taken out so far by {TAKEN_OUT.get(name, name)}") for name in sorted(taken_out)
    ]
    rows.append(("drift", COLUMNS["drift"]))
    width = max(len(name) for name, _ in rows)
    lines = [f"time in {time_unit}, energies in {energy_unit} (unit masses):"]
    lines += [f"  {name:<{width}}  {meaning}" for name, meaning in rows]
    return "\n".join(lines)
