"""The 2-D springs gallery of the p5.js teaching page (seed ``004``).

Units are the page's: pixels and animation frames, unit masses, forces in
px/frame² (gravity 0.1 means v grows by 0.1 px/frame each frame). The page's
canvas is 600×400 px with y pointing down; here y points up (y = 400 - y_page),
so gravity is (0, -g). Rest lengths are the distances at creation, as on the page.

Every scene takes ``model``: "physical" (default) steps Newton's law with
`VelocityVerlet` and turns the page's velocity factor per frame into the
exact drag v ← v·exp(-rate·dt) with rate = -ln(damping) per frame;
"frame" is the page's own ``draw()`` (`FrameEuler`), reproduced frame for frame:
external forces, damping, speed cap, the page's wall rule, move, then the
springs at the new positions. Where the physical model differs from the page:

- no dead zone: the page's springs do nothing while their ends are within
  1 px, so two particles 0.5 px apart on a long spring stay put there, while
  the physical spring pushes them apart to its rest length;
- no speed cap: past the stable step the physical model blows up and says so,
  the page's model oscillates at 10 px/frame;
- walls: the page tests the position before the move, turns the velocity
  inward and never moves the particle back (it ends up to one frame's move
  past the wall and keeps bouncing there); the physical walls put a particle
  back on the wall after the move with a bounce that keeps its energy;
- order: the page's springs act at the end of a frame and move the particles
  in the next one (none in the first frame); the physical model is Newton's law.

Without walls, speed cap and dead zone, both have the same equilibria.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from .. import Body, Constraint, Force, Gravity, Simulation, VelocityVerlet, rotation_matrix
from ..engine.model.units import PAGE
from ..interaction import Drag, Prescribed, Walls
from .frame_model import FrameEuler

WIDTH, HEIGHT = 600.0, 400.0  # the page's canvas (px)
MODELS = ("physical", "frame")
WALLS = ("none", "hard", "periodic")


def simulation(
    body: Body,
    *,
    model: str = "physical",
    damping: float = 0.96,
    gravity: float = 0.0,
    walls: str = "none",
    max_speed: float = 10.0,
    dt: float = 1.0,
    extra: Sequence[Force | Constraint] = (),
) -> Simulation:
    """A gallery body on the page's canvas: gravity (px/frame²), damping per frame, walls.

    The page's per-frame model (``model="frame"``) is not a physical one, so its
    runs skip the energy ledger's per-mechanism bookkeeping (``ledger=False``:
    the frames still record the energies) and stay fast enough to drag live.
    """
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}; choose one of {', '.join(MODELS)}")
    if walls not in WALLS:
        raise ValueError(f"unknown walls {walls!r}; choose one of {', '.join(WALLS)}")
    if not 0.0 < damping <= 1.0:
        raise ValueError(f"damping is a velocity factor per frame in (0, 1], got {damping}")
    forces: list[Force | Constraint] = [Gravity((0.0, -gravity))] if gravity else []
    integrator: FrameEuler | VelocityVerlet
    if model == "frame":  # the page's walls are part of its draw()
        rule = None if walls == "none" else walls
        integrator = FrameEuler(damping, max_speed, walls=rule, upper=(WIDTH, HEIGHT))
    else:
        integrator = VelocityVerlet()
        if walls != "none":  # before the drag, which then acts on the bounced velocity
            mode = "reflect" if walls == "hard" else "periodic"
            forces.append(Walls((0.0, 0.0), (WIDTH, HEIGHT), mode))
        if damping < 1.0:
            forces.append(Drag(-math.log(damping)))
    sim = Simulation(body, integrator, dt, [*forces, *extra], ledger=model != "frame")
    sim.units = PAGE
    return sim


def two_particles(
    *, stiffness: float = 0.1, pull: float = 50.0, damping: float = 0.96, model: str = "physical"
) -> Simulation:
    """Springs 1: two particles 100 px apart, the right one pulled ``pull`` px further out."""
    body = Body.from_arrays([[250.0, 200.0], [350.0, 200.0]], [[0, 1]], stiffness=stiffness)
    body.positions[1, 0] += pull
    return simulation(body, model=model, damping=damping)


def triangle(
    *,
    stiffness: float = 0.1,
    gravity: float = 0.1,
    damping: float = 0.96,
    walls: str = "hard",
    model: str = "physical",
) -> Simulation:
    """A triangle (250, 200), (350, 200), (300, 286) (page coordinates) falling in hard walls."""
    corners = [[250.0, HEIGHT - 200.0], [350.0, HEIGHT - 200.0], [300.0, HEIGHT - 286.0]]
    body = Body.from_arrays(corners, [[0, 1], [1, 2], [0, 2]], stiffness=stiffness)
    return simulation(body, model=model, damping=damping, gravity=gravity, walls=walls)


def hanging_particle(
    *, stiffness: float = 0.1, gravity: float = 0.5, damping: float = 0.96, model: str = "physical"
) -> Simulation:
    """One fixed particle at (300, 150) (page) holding another 100 px below it."""
    body = Body.from_arrays(
        [[300.0, HEIGHT - 150.0], [300.0, HEIGHT - 250.0]],
        [[0, 1]],
        fixed=[True, False],
        stiffness=stiffness,
    )
    return simulation(body, model=model, damping=damping, gravity=gravity)


def rope(
    *,
    count: int = 18,
    spacing: float = 12.0,
    stiffness: float = 0.1,
    gravity: float = 0.1,
    damping: float = 0.96,
    model: str = "physical",
) -> Simulation:
    """Springs 2: ``count`` particles in a horizontal line from a fixed one at the top
    middle (300, 20) (page); it swings down and hangs inside the canvas: 17 links of
    12 px plus Hooke's stretch Σ i·m g/K = 153 px put the end 357 px below the top one."""
    x = WIDTH / 2 + spacing * np.arange(count)
    body = Body.from_arrays(
        np.column_stack([x, np.full(count, HEIGHT - 20.0)]),
        _chain(count),
        fixed=np.arange(count) == 0,
        stiffness=stiffness,
    )
    return simulation(body, model=model, damping=damping, gravity=gravity)


def hanging_rope(
    *,
    count: int = 18,
    rest_length: float = 40.0,
    span: float = 400.0,
    stiffness: float = 0.1,
    gravity: float = 0.1,
    damping: float = 0.96,
    model: str = "physical",
) -> Simulation:
    """A rope of ``count`` particles with both ends fixed ``span`` px apart: a catenary.

    The links (rest ``rest_length``) start on the straight line between the
    ends, squeezed when the rope is longer than the span, and the rope sags.
    """
    x = (WIDTH - span) / 2 + np.linspace(0.0, span, count)
    ends = (np.arange(count) == 0) | (np.arange(count) == count - 1)
    body = Body.from_arrays(
        np.column_stack([x, np.full(count, HEIGHT - 50.0)]),
        _chain(count),
        fixed=ends,
        stiffness=stiffness,
        rest_lengths=rest_length,
    )
    return simulation(body, model=model, damping=damping, gravity=gravity)


def wheel(
    *,
    spokes: int = 12,
    radius: float = 60.0,
    stiffness: float = 0.1,
    gravity: float = 0.1,
    damping: float = 0.96,
    walls: str = "hard",
    model: str = "physical",
) -> Simulation:
    """Springs 3: a ring of ``spokes`` particles, each joined to its neighbours and to a hub."""
    ring = _circle(spokes, radius, (300.0, 250.0))
    hub = spokes
    pairs = [*_ring_chords(spokes, (1,)), *([i, hub] for i in range(spokes))]
    body = Body.from_arrays(np.vstack([ring, [300.0, 250.0]]), pairs, stiffness=stiffness)
    return simulation(body, model=model, damping=damping, gravity=gravity, walls=walls)


def blob(
    *,
    count: int = 60,
    radius: float = 100.0,
    chords: Sequence[int] = (3, 5, 7, 11),
    stiffness: float = 0.1,
    gravity: float = 0.1,
    damping: float = 0.93,
    walls: str = "hard",
    model: str = "physical",
) -> Simulation:
    """Springs 3: a bouncy bag, ``count`` points on a circle, point i joined to i + ``chords``."""
    body = Body.from_arrays(
        _circle(count, radius, (300.0, 250.0)), _ring_chords(count, chords), stiffness=stiffness
    )
    return simulation(body, model=model, damping=damping, gravity=gravity, walls=walls)


def mesh(
    *,
    shape: Sequence[int] = (10, 10),
    spacing: float = 30.0,
    diagonals: bool = True,
    tilt: float = 0.0,
    stiffness: float = 0.08,
    gravity: float = 0.1,
    damping: float = 0.93,
    walls: str = "hard",
    model: str = "physical",
) -> Simulation:
    """Springs 4: a square mesh with both diagonals in every cell (342 springs for 10×10).

    Without ``diagonals`` the squares have no shear stiffness: dropped upright the
    mesh stands on its vertical springs, but tilted by ``tilt`` degrees it folds flat.
    """
    body = _mesh_body(shape, spacing, diagonals, stiffness)
    body.rotate(rotation_matrix(tilt))
    return simulation(body, model=model, damping=damping, gravity=gravity, walls=walls)


def driven_mesh(
    *,
    shape: Sequence[int] = (10, 10),
    spacing: float = 20.0,
    amplitude: float = 40.0,
    period: float = 90.0,
    noise: float = 25.0,
    seed: int = 0,
    stiffness: float = 0.08,
    gravity: float = 0.1,
    damping: float = 0.93,
    model: str = "physical",
) -> Simulation:
    """Springs 5: the mesh hanging from its top-middle particle, which a driver moves.

    The driver's home is 80 px below the top of the canvas; with the defaults the
    mesh (20 px cells) hangs and swings inside the canvas.

    The driver is a vertical sine (``amplitude`` px, ``period`` frames) plus
    smooth random wandering of about ``noise`` px (a few sines with random
    frequencies and phases from ``seed``, standing in for the page's Perlin noise).
    """
    body = _mesh_body(shape, spacing, True, stiffness)
    rows, cols = (int(n) for n in shape)
    driven = (cols // 2) * rows + rows - 1  # top row, middle column
    body.positions = body.positions + (0.0, HEIGHT - 80.0 - body.positions[driven, 1])
    home = body.positions[driven].copy()
    wander = _smooth_noise(np.random.default_rng(seed), noise, period)

    def path(t: float) -> np.ndarray:
        bounce = np.array([0.0, amplitude * math.sin(2 * math.pi * t / period)])
        return home + bounce + wander(t)

    return simulation(
        body,
        model=model,
        damping=damping,
        gravity=gravity,
        extra=[Prescribed([driven], path)],
    )


def truss(
    *,
    segments: int = 16,
    length: float = 30.0,
    width: float = 15.0,
    stiffness: float = 0.1,
    gravity: float = 0.1,
    damping: float = 0.96,
    walls: str = "hard",
    model: str = "physical",
) -> Simulation:
    """Springs 6: a narrow truss (a "worm") of ``segments`` braced cells, dropped on the floor."""
    cells = Body.grid((segments + 1, 2), neighbours=(1, 2))
    body = Body.from_arrays(
        (60.0, 60.0) + cells.positions * (length, width),
        np.column_stack([cells.edges().a, cells.edges().b]),
        stiffness=stiffness,
    )
    return simulation(body, model=model, damping=damping, gravity=gravity, walls=walls)


# ---------------------------------------------------------------------- helpers
def _chain(count: int) -> np.ndarray:
    """Index pairs (i, i + 1) of a chain of ``count`` particles."""
    return np.column_stack([np.arange(count - 1), np.arange(1, count)])


def _circle(count: int, radius: float, centre: Sequence[float]) -> np.ndarray:
    """``count`` points evenly on a circle (px)."""
    angle = 2 * np.pi * np.arange(count) / count
    return np.asarray(centre) + radius * np.column_stack([np.cos(angle), np.sin(angle)])


def _ring_chords(count: int, offsets: Sequence[int]) -> np.ndarray:
    """Pairs (i, i + o mod count) around a ring, one per chord."""
    i = np.arange(count)
    pairs = [np.column_stack([i, (i + o) % count]) for o in offsets]
    unique = {tuple(sorted(p)) for p in np.vstack(pairs).tolist()}
    return np.array(sorted(unique))


def _mesh_body(shape: Sequence[int], spacing: float, diagonals: bool, stiffness: float) -> Body:
    """A 2-D grid (rows along y) centred on the canvas, springs at their rest lengths."""
    shape = tuple(int(n) for n in shape)
    origin = ((WIDTH - spacing * (shape[0] - 1)) / 2, 100.0)
    return Body.grid(
        shape, spacing, stiffness, neighbours=(1, 2) if diagonals else (1,), origin=origin
    )


def _smooth_noise(
    rng: np.random.Generator, size: float, period: float
) -> Callable[[float], np.ndarray]:
    """A smooth random 2-D wander of about ``size`` px: four slow sines per axis."""
    frequencies = rng.uniform(0.2, 1.0, (4, 2)) / period
    phases = rng.uniform(0.0, 2 * np.pi, (4, 2))
    weights = size / 2.0

    def wander(t: float) -> np.ndarray:
        return weights * np.sin(2 * np.pi * frequencies * t + phases).sum(axis=0) / 2.0

    return wander
