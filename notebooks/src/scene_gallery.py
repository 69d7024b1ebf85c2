# %% [markdown]
# # The 2-D springs gallery
#
# A p5.js teaching page builds its examples from two pieces: particles and
# springs with Hooke's law $F = -k\,x$, rest length = the distance at creation.
# Its units are pixels and animation frames ($\Delta t = 1$ frame), masses are 1,
# and each frame it does
#
# $$\mathbf{v} \mathrel{+}= \mathbf{g}, \qquad \mathbf{v} \mathrel{*}= d, \qquad
#   \lVert\mathbf{v}\rVert \le 10\ \text{px/frame}, \qquad \mathbf{x} \mathrel{+}= \mathbf{v},
#   \qquad \mathbf{v} \mathrel{+}= \mathbf{F}_\text{springs}(\mathbf{x})/m$$
#
# in that order: the springs act at the end of a frame and move the particles
# in the next one (in the first frame only gravity acts). The velocity factor
# $d$ is 0.96 to start ("never higher than 1"); hard walls turn the velocity
# inward when the position *before* the move is past a wall and never move the
# particle back, so it may end up to one frame's move outside; periodic walls
# wrap the position before the move; springs do nothing while their ends are
# within 1 px; the user drags the nearest particle with the mouse.
# `msdlab.scenes.gallery` has every example, each with two models:
# `model="frame"` is the page's own update (`FrameEuler`), checked frame by
# frame against the page's JavaScript run under node, `model="physical"`
# (default) steps Newton's law with velocity Verlet and turns $d$ into the exact
# drag $\mathbf{v} \leftarrow \mathbf{v}\,e^{-r\Delta t}$ with $r = -\ln d$ per frame.
# Here $y$ points up (the page's points down). The physical model has no dead
# zone, no speed cap and walls that put a particle back on the wall with a
# bounce that keeps its energy.

# %%
from collections.abc import Callable

import matplotlib.pyplot as plt
import numpy as np
from IPython.display import HTML
from scipy.optimize import curve_fit

import msdlab as msd
from msdlab import viz
from msdlab.scenes import SCENES, gallery

# %% [markdown]
# ## The gallery after 300 frames

# %%
scenes = [scene for scene in SCENES.values() if scene.unit == "frames"]
fig, axes = plt.subplots(2, 5, figsize=(16, 6))
after = {}
for scene, ax in zip(scenes, axes.flat):
    after[scene.name] = sim = scene.build()
    sim.run(steps=300, record_every=300)
    viz.BodyView(ax, sim.body, colorbar=False)
    ax.set(xlim=(0, gallery.WIDTH), ylim=(0, gallery.HEIGHT), title=scene.name)
plt.show()
for name, sim in after.items():
    print(viz.body_in_words(sim.body, title=name))

# %% [markdown]
# ## Two models, one equilibrium
#
# The page's update is not Newton's law in time (its damping depends on the
# frame rate, the speed cap clips what the forces say), but at rest the forces
# balance the same way: a particle hanging from a fixed one by a spring of
# $k = 0.1$ under gravity $g = 0.5$ px/frame² stretches it by $mg/k = 5$ px.

# %%
# NBVAL_CHECK_OUTPUT
for model in gallery.MODELS:
    sim = gallery.hanging_particle(model=model)
    sim.run(steps=2000, record_every=2000)
    stretch = np.linalg.norm(np.diff(sim.body.positions, axis=0)) - 100.0
    print(f"{model:<8} model: the spring stretches by {stretch:.2f} px")

# %% [markdown]
# ## The hanging rope is a catenary
#
# A chain fixed at both ends settles where gravity and tension balance. An
# inextensible chain hangs as $y = y_0 + a\,(\cosh((x - x_0)/a) - 1)$; this one
# is elastic (18 particles, links of rest length 40 px over a 400 px span), and
# still fits the curve to within 1 % of its sag:

# %%
# NBVAL_CHECK_OUTPUT
sim = gallery.hanging_rope()
sim.run(steps=5000, record_every=5000)
x, y = sim.body.positions.T


def catenary(xs: np.ndarray, a: float, x0: float, y0: float) -> np.ndarray:
    return y0 + a * (np.cosh((xs - x0) / a) - 1.0)


(a, x0, y0), _ = curve_fit(catenary, x, y, p0=(200.0, 300.0, y.min()))
sag = y[0] - y.min()
print(f"sag {sag:.1f} px, lowest point at x = {x0:.1f} px (the middle of the span)")
miss = np.max(np.abs(catenary(x, a, x0, y0) - y))
print(f"fits a catenary to within 1 % of the sag: {miss < 0.01 * sag}")

# %%
fig, ax = plt.subplots(figsize=(7, 3))
fine = np.linspace(x.min(), x.max(), 200)
ax.plot(fine, catenary(fine, a, x0, y0), label=f"catenary, a = {a:.0f} px")
ax.plot(x, y, "o", label="the rope's particles")
ax.set(xlabel="x (px)", ylabel="y (px)", aspect="equal")
ax.legend()
plt.show()
print(viz.plot_in_words(ax))

# %% [markdown]
# ## The speed cap hides the instability
#
# The page warns that a large $k$ "explodes" under its Euler update. With
# $k = 1.5$ the rope's stiffest mode has $\omega\,\Delta t = 2.4 > 2$: no explicit
# scheme is stable at one step per frame. The physical model stops and says
# so; the page's update never blows up, because the speed cap holds every
# particle at 10 px per frame, but the rope it draws is torn apart.

# %%
try:
    gallery.rope(stiffness=1.5, damping=1.0).run(steps=400)
except msd.SimulationDiverged as error:
    print(error)

# %%
# NBVAL_CHECK_OUTPUT
capped = gallery.rope(stiffness=1.5, damping=1.0, model="frame")
run = capped.run(steps=400, record_every=1)
moves = np.linalg.norm(np.diff(run.positions, axis=0), axis=2)
links = np.linalg.norm(np.diff(run.positions[-100:], axis=1), axis=2)
print(f"frame model, largest move: {moves.max():.1f} px/frame")
print(f"links stretched or squeezed by more than 20 %: {np.max(np.abs(links / 12.0 - 1.0)) > 0.2}")

# %% [markdown]
# ## A bouncing blob
#
# Sixty points on a circle, each joined to its 3rd, 5th, 7th and 11th
# neighbour, falling in hard walls:

# %%
run = gallery.blob().run(steps=400, record_every=5)
HTML(viz.to_html(run, max_frames=60, time_unit="frames"))

# %% [markdown]
# ## Dragging
#
# On the page you grab the nearest particle and drag it. `viz.show(sim)` does
# the same here: the browser draws the mesh at its own frame rate while Python
# steps it at the page's pace (60 frames a second) in the background. Press near
# a particle and drag; let go and it keeps the hand's velocity, not the spring
# forces it held against (the page set the position only, so a released particle
# flung away). The buttons pause, step and reset it; the sliders change the
# stiffness, the damping, gravity and $\Delta t$ between two steps; the bars on
# the right are the energy ledger as it runs (kinetic, elastic, gravitational
# from the floor, and what the drag and the walls took out). It works offline in
# JupyterLab and in VS Code's notebooks.

# %%
live = viz.show(gallery.mesh(), steps_per_second=60)  # the page's pace

# %% [markdown]
# The same drag by script: the top-right corner of the mesh is taken in hand,
# pulled 150 px to the left, and let go, with the same `msd.Grab` as the mouse.


# %%
def drag_corner(
    sim: msd.Simulation, shift: np.ndarray, frames: int
) -> Callable[[msd.Simulation], None]:
    """A callback for ``sim.run`` that holds the mesh's top-right corner, moves it by
    ``shift`` (px) over ``frames`` frames and then lets go."""
    corner = int(np.argmax(sim.body.positions.sum(axis=1)))
    grab = msd.Grab()
    sim.constraints.append(grab)
    grab.hold(sim.body, corner)
    start = sim.body.positions[corner].copy()

    def hand(sim: msd.Simulation) -> None:
        if sim.step_count <= frames:
            grab.move(start + sim.step_count / frames * shift)
        elif grab.particle is not None:
            grab.release()

    return hand


sim = gallery.mesh()
hand = drag_corner(sim, np.array([-150.0, 0.0]), frames=60)
run = sim.run(steps=240, record_every=3, callback=hand)
HTML(viz.to_html(run, max_frames=60, time_unit="frames"))

# %% [markdown]
# ## Why a dragged mesh can fold, and how to prevent it
#
# Pull a corner hard across the mesh and let go: some cells may stay turned
# inside out. A spring knows only its length, $E = \tfrac12 k\,(\lVert\mathbf{x}_a -
# \mathbf{x}_b\rVert - L)^2$, not which side of the other particles it lies on: a
# cell flipped over its diagonal has the same edge lengths as before, so its
# springs are at rest and nothing pushes it back. The mesh has no *area*
# stiffness, no energy that grows when a cell's signed area shrinks through zero.
# The cell below pulls a corner towards the middle, once gently (60 px in 60
# frames) and once thrown (400 px in 10 frames), lets go, and counts the cells
# turned inside out (signed area of the other sign) once the mesh has settled.
#
# To keep a mesh from folding: drag gently (the springs then pull every cell back
# before it passes through zero area); use stiffer springs, or more steps per
# frame with a smaller step, so a cell resists being squashed; or add an area
# (or volume, in 3-D) term $E = \tfrac12 k_A\,(A - A_0)^2$ per cell, as finite
# elements and cloth simulators do, whose force grows as a cell is squashed and
# so stops it from turning over.


# %%
def inverted_cells(sim: msd.Simulation, shape: tuple[int, int] = (10, 10)) -> int:
    """Cells of the mesh whose signed area (shoelace formula) is negative: turned over."""
    grid = sim.body.positions.reshape(shape[0], shape[1], 2)
    corners = [grid[:-1, :-1], grid[:-1, 1:], grid[1:, 1:], grid[1:, :-1]]
    area = sum(
        a[..., 0] * b[..., 1] - b[..., 0] * a[..., 1]
        for a, b in zip(corners, corners[1:] + corners[:1])
    )
    return int(np.sum(np.sign(area) != np.sign(np.median(area))))


def pull_and_let_go(pull: float, frames: int) -> msd.Simulation:
    """The mesh (no gravity) after its top-right corner is moved ``pull`` px left and down
    in ``frames`` frames, let go, and left to settle for 600 frames in all."""
    sim = gallery.mesh(gravity=0.0)
    hand = drag_corner(sim, np.array([-pull, -pull]), frames)
    sim.run(steps=600, record_every=600, callback=hand)
    return sim


turned_over = {}
for pull, frames in ((60.0, 60), (400.0, 10)):
    turned_over[frames] = inverted_cells(pull_and_let_go(pull, frames))
    count = turned_over[frames]
    print(f"corner moved {pull:.0f} px in {frames} frames: {count} of 81 cells turned over")

# %%
# NBVAL_CHECK_OUTPUT
# How many cells stay turned over depends on rounding (a thrown mesh moves chaotically);
# whether it folds at all does not.
print(
    f"gently dragged mesh folded: {turned_over[60] > 0}; thrown mesh folded: {turned_over[10] > 0}"
)
