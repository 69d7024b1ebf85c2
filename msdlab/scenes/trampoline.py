"""Trampoline: a ball dropped on a square net whose perimeter is held (seed ``000``, MATLAB report).

The report's control case: a 7×7 net of nodes 1 m apart with links of rest
length 0.95 m (so the net is pre-tensioned), k = 999 N/m, perimeter fixed; a
1 kg ball of radius 0.5 m let go from (3, 3, 1.5) m under g = -9.8 m/s²,
dt = 1 ms, 5 s. Its six experiments are in `EXPERIMENTS`.

The model keeps the report's picture but not its code's physics errors:
every node has its own mass (the code divided the net's forces by the ball's
mass), link forces act along the links (not from atan and sign tables), and
the ball is a particle of the body touching the nodes through `SphereContact`,
so contact forces are equal and opposite, with a contact stiffness of its own.
As in the report, the links themselves do not touch the ball: only nodes do.

With this model the report's outcomes hold (see `run_experiment`): a heavier
ball and softer links sink deeper, stiffer links less; a ball of radius
0.5 m fits through a cell (half diagonal 0.71 m), so dropped off a node it rolls
off and falls through, while one of radius 1 m is caught between four nodes.
The ball placed exactly on a node stays there only by symmetry (it balances
on a point). On the 11×11 net the ball ends nearer the centre, but mostly for
the same reason as on the 7×7 net: landing beside the top of a node pushes it
in +x+y into the next cell, which here lies toward the centre. The net is indeed
softer near its centre (a ball resting there sits lower), but that pull only
shifts a resting ball a few millimetres within its cell: the nodes around the
cell hold it where it lands.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import Body, Gravity, Integrator, Simulation, VelocityVerlet
from ..engine.model.lattice import grid_pairs, neighbour_offsets
from ..interaction import Drag, SphereContact

BALL = -1  # the ball is the last particle of the body


def trampoline(
    *,
    size: int = 7,
    stiffness: float = 999.0,
    rest_length: float = 0.95,
    node_mass: float = 0.02,
    link_damping: float = 2.0,
    ball_mass: float = 1.0,
    ball_radius: float = 0.5,
    ball_position: Sequence[float] = (3.0, 3.0, 1.5),
    contact_stiffness: float = 1.0e4,
    drag: float = 1.0,
    gravity: float = -9.8,
    dt: float = 1.0e-3,
    integrator: Integrator | None = None,
) -> Simulation:
    """A ball (the last particle, `BALL`) over a ``size``×``size`` net with spacing 1 m, z up.

    Units: m, kg, s, N/m. Choices the report leaves open, and why:

    - ``node_mass`` 0.02 kg: the report takes the net as massless, which no
      explicit scheme can step; 25 free nodes of 20 g weigh half the ball.
    - ``integrator`` `VelocityVerlet` (default): symplectic, so the energy
      stays bounded without damping; the predicted stable dt is ≈ 4 ms, four
      times the report's 1 ms. The report's forward Euler (`ExplicitEuler`)
      gains energy every step on undamped springs (here the run diverges
      after about 6 s); it needs a dashpot c > k·dt on every mode, and the links' dashpots
      (``link_damping``, N·s/m) cannot damp the net's sideways waves.
    - ``drag`` 1/s: air and net losses lumped into v ← v·exp(-drag·dt) on
      every particle (exact, so stable at any dt, and booked in the energy
      ledger). Without it a lossless net keeps bouncing the ball for ever and
      no resting place can be read off; it does not change where the ball rests.
    - ``contact_stiffness`` 10⁴ N/m (the report reused k): the ball sinks
      m·g/10⁴ ≈ 1 mm into a node instead of 1 cm, whatever the links' k.
    """
    if isinstance(size, bool) or not isinstance(size, int) or size < 3:
        raise ValueError(f"the net needs size >= 3 nodes per side, got {size!r}")
    ij = np.stack(np.meshgrid(np.arange(size), np.arange(size), indexing="ij"), axis=-1)
    ij = ij.reshape(-1, 2)
    pairs = grid_pairs((size, size), neighbour_offsets(2, (1,)))
    body = Body.from_arrays(
        np.column_stack([ij, np.zeros(len(ij))]).astype(float),
        pairs,
        masses=node_mass,
        fixed=np.any((ij == 0) | (ij == size - 1), axis=1),
        stiffness=stiffness,
        rest_lengths=rest_length,
        damping=link_damping,
    )
    (ball,) = body.add_particles([ball_position], masses=ball_mass)
    forces = [
        Gravity((0.0, 0.0, gravity)),
        SphereContact(int(ball), ball_radius, contact_stiffness),
        Drag(drag),
    ]
    return Simulation(body, integrator or VelocityVerlet(), dt, forces)


@dataclass(frozen=True)
class Experiment:
    """One run of the report: its name, what changed, and the keyword arguments."""

    name: str
    description: str
    settings: dict


EXPERIMENTS = {
    e.name: e
    for e in (
        Experiment("control", "1 kg ball, r = 0.5 m, on the centre node", {}),
        Experiment("heavier", "5 kg ball", {"ball_mass": 5.0}),
        Experiment(
            "off-centre",
            "dropped 0.1 m off the node in x and y",
            {"ball_position": (3.1, 3.1, 1.5)},
        ),
        Experiment(
            "off-centre-big",
            "off-centre, radius 1 m (wider than a cell)",
            {"ball_position": (3.1, 3.1, 1.5), "ball_radius": 1.0},
        ),
        Experiment(
            "net-11x11",
            "11×11 net, off-centre ball of radius 1 m",
            {"size": 11, "ball_position": (3.1, 3.1, 1.5), "ball_radius": 1.0},
        ),
        Experiment("k-450", "softer links, k = 450 N/m", {"stiffness": 450.0}),
        Experiment("k-1250", "stiffer links, k = 1250 N/m", {"stiffness": 1250.0}),
    )
}


@dataclass(frozen=True)
class Outcome:
    """What happened to the ball in one experiment (m)."""

    experiment: Experiment
    start: np.ndarray  # ball centre at t = 0
    end: np.ndarray  # ball centre at the end
    deepest: float  # lowest height of the ball centre during the run
    resting: float  # mean height of the ball centre over the last second
    net_centre: np.ndarray  # (x, y) of the middle of the net
    fate: str  # "rests on a node", "caught between four nodes", "fell through the net"

    def row(self) -> str:
        x, y, z = self.end
        return (
            f"{self.experiment.name:<15} {self.experiment.description:<44} "
            f"{self.deepest:>8.3f} {self.resting:>8.3f} {x:>6.2f} {y:>6.2f} {z:>8.2f}  {self.fate}"
        )


def run_experiment(experiment: Experiment, duration: float = 5.0, **overrides: object) -> Outcome:
    """Run one experiment for ``duration`` seconds and classify where the ball ended."""
    sim = trampoline(**{**experiment.settings, **overrides})
    trajectory = sim.run(duration=duration, record_every=10)
    ball = trajectory.positions[:, BALL]
    last_second = trajectory.times >= trajectory.times[-1] - min(1.0, duration / 2)
    nodes = trajectory.positions[-1, :BALL]
    middle = (math.isqrt(len(nodes)) - 1) / 2  # nodes are 1 m apart from (0, 0)
    return Outcome(
        experiment=experiment,
        start=ball[0],
        end=ball[-1],
        deepest=float(ball[:, 2].min()),
        resting=float(ball[last_second, 2].mean()),
        net_centre=np.array([middle, middle]),
        fate=_fate(ball[-1], nodes),
    )


def _fate(ball: np.ndarray, nodes: np.ndarray) -> str:
    """Where the ball ended, from its centre and the node positions (spacing 1 m)."""
    if ball[2] < nodes[:, 2].min() - 0.5:
        return "fell through the net"
    offset = np.abs(ball[:2] - np.round(ball[:2]))
    if np.all(offset < 0.1):
        return "rests on a node"
    if np.all(np.abs(offset - 0.5) < 0.1):
        return "caught between four nodes"
    return "on the net"


def experiment_table(outcomes: Sequence[Outcome]) -> str:
    """The outcomes as a text table, heights of the ball centre in m."""
    header = (
        f"{'experiment':<15} {'what changed':<44} {'deepest':>8} {'resting':>8} "
        f"{'x end':>6} {'y end':>6} {'z end':>8}  fate"
    )
    return "\n".join([header, *(o.row() for o in outcomes)])
