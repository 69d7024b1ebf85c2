# %% [markdown]
# # Task 2: springs between axis neighbours
#
# > *Extend the template code with an acceleration/spring force term (per
# > particle) corresponding to equations (1.1) and (1.2). Get your code running
# > using only springs with rest length 1.*
#
# Every particle is joined by a spring to its axis neighbours
# $(i\pm1, j, k)$, $(i, j\pm1, k)$, $(i, j, k\pm1)$ where they exist: 6 inside
# the grid, 5, 4 or 3 on a face, edge or corner. With unit masses
#
# $$\mathbf{a}_i = \sum_j \mathbf{f}_{ij}, \tag{1.1}$$
# $$\mathbf{f}_{ij} = k\,(l_{ij} - \lVert\mathbf{x}_i - \mathbf{x}_j\rVert)\,
#   \frac{\mathbf{x}_i - \mathbf{x}_j}{\lVert\mathbf{x}_i - \mathbf{x}_j\rVert}. \tag{1.2}$$
#
# "Rest length 1" means one grid spacing: $l_{ij} = h$ in world units. A
# stretched spring ($\lVert\mathbf{x}_i - \mathbf{x}_j\rVert > l_{ij}$) pulls
# $i$ toward $j$; particle $j$ feels $-\mathbf{f}_{ij}$. You write
# `spring_acceleration(x, spacing, stiffness)` in `task2.py`; the given
# `msd_kernel` adds it to the template's step.

# %%
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import HTML, display

import msdlab as msd
from msdlab import viz
from msdlab.course.notebook import Course

course = Course()  # your assignments/ (MSDLAB_IMPL=solutions: the reference answers)
task2 = course.task(2)
print(f"task files: {course.label}")
h, k = task2.SPACING, task2.STIFFNESS


def show(vector: np.ndarray) -> str:
    """A vector rounded to 4 decimals, without negative zeros."""
    return "(" + ", ".join(f"{c:.4f}" for c in np.round(vector, 4) + 0.0) + ")"


# %% [markdown]
# ## At rest, stretched, squeezed
#
# A $3 \times 3 \times 3$ grid at rest must feel no force. Stretched by 10 %
# about its centre, every spring is longer than $h$ and pulls: the corners are
# pulled inward, the centre particle is pulled equally from all sides.

# %%
# NBVAL_CHECK_OUTPUT
x = task2.initial_grid((3, 3, 3))
centre = x.reshape(-1, 3).mean(axis=0)
with course.attempt():
    at_rest = task2.spring_acceleration(x, h, k)
    print("at rest, no force:", np.abs(at_rest).max() < 1e-12)
    stretched = task2.spring_acceleration(centre + 1.1 * (x - centre), h, k)
    print("stretched 10 %: corner (0, 0, 0)", show(stretched[0, 0, 0]))
    print("                centre (1, 1, 1)", show(stretched[1, 1, 1]))
    print("                corner (2, 2, 2)", show(stretched[2, 2, 2]))
    squeezed = task2.spring_acceleration(centre + 0.9 * (x - centre), h, k)
    print("squeezed 10 %:  corner (0, 0, 0)", show(squeezed[0, 0, 0]))

# %% [markdown]
# Each corner has three springs, each stretched by $0.1h = 0.01$, so each pulls
# with $k \cdot 0.01 = 0.005$ along its axis.
#
# ## Against the engine, and Newton's third law
#
# The engine's `Body.grid` with `neighbours=(1,)` has the same springs. On a
# randomly deformed grid both must give the same accelerations, and since
# every spring pushes its two ends equally and oppositely, the accelerations
# of all (unit-mass) particles must add up to zero.

# %%
# NBVAL_CHECK_OUTPUT
rng = np.random.default_rng(2)
deformed = task2.initial_grid((4, 5, 3)) + 0.02 * rng.standard_normal((4, 5, 3, 3))
engine = msd.Body.grid((4, 5, 3), spacing=h, stiffness=k, neighbours=(1,))
expected = msd.Dynamics(engine).acceleration(deformed.reshape(-1, 3), np.zeros((60, 3)))
with course.attempt():
    yours = task2.spring_acceleration(deformed, h, k)
    print("same as the engine:", np.allclose(yours.reshape(-1, 3), expected, atol=1e-12))
    print("accelerations add up to zero:", np.allclose(yours.sum(axis=(0, 1, 2)), 0, atol=1e-12))

# %% [markdown]
# ## The classic bug: rest length 1 in world units
#
# The grid spacing is $h = 2/N = 0.1$. A rest length of 1.0 instead of $h$
# makes every spring ten times too long at rest: the grid starts squeezed, and
# it blows apart the moment it is let go.

# %%
# NBVAL_CHECK_OUTPUT
with course.attempt():
    wrong = task2.spring_acceleration(x, 1.0, k)
    print(f"at rest with l = 1: largest push {np.abs(wrong).max():.2f} (it should be 0)")

# %% [markdown]
# ## Energy is conserved
#
# Springs are conservative: in free flight (no gravity, no floor) a wobbling
# grid keeps its kinetic + elastic energy. Here your accelerations drive the
# template's Verlet step, eq. (1.3), for 600 steps; the velocity for the
# kinetic energy is the central difference $(\mathbf{x}_{n+1} - \mathbf{x}_{n-1})/2\Delta t$.

# %%
# NBVAL_CHECK_OUTPUT
dt = task2.DT


def free_flight(start: np.ndarray, steps: int) -> np.ndarray:
    """Positions (steps + 1, particles, 3) from rest, eq. (1.3) with your accelerations."""
    path = [start, start]  # at rest: old = current
    for _ in range(steps):
        path.append(2 * path[-1] - path[-2] + task2.spring_acceleration(path[-1], h, k) * dt**2)
    return np.array(path[1:]).reshape(steps + 1, -1, 3)


wobbling = task2.initial_grid((5, 5, 5)) + 0.01 * rng.standard_normal((5, 5, 5, 3))
body = msd.Body.grid((5, 5, 5), spacing=h, stiffness=k, neighbours=(1,))
with course.attempt():
    path = free_flight(wobbling, 601)
    speed = (path[2:] - path[:-2]) / (2 * dt)
    kinetic = 0.5 * np.sum(speed**2, axis=(1, 2))
    elastic = np.array([msd.elastic_energy(body, frame) for frame in path[1:-1]])
    total = kinetic + elastic
    print(f"total energy stays within 1 % of its start: {np.ptp(total) < 0.01 * total[0]}")

# %%
with course.attempt():
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for name, values in (("kinetic", kinetic), ("elastic", elastic), ("total", total)):
        ax.plot(values, label=name)
    ax.set(xlabel="step", ylabel="energy", title="A free grid of axis springs wobbling")
    ax.legend()
    plt.show()
    print(viz.plot_in_words(ax))

# %% [markdown]
# ## The template with springs
#
# `task2.run` and `task2.msd_kernel` are the template with your springs. A
# $8 \times 8 \times 8$ grid (spacing $h$, $k = 0.5$) is dropped from
# $y = {{ y0 }}$ and followed for 1200 steps.


# %%
def drop(shape: tuple[int, int, int], steps: int, every: int) -> np.ndarray:
    """Positions (frames, particles, 3) every ``every`` steps of the template with your springs."""
    current = task2.initial_grid(shape)
    old, new = current.copy(), np.empty_like(current)
    frames = [current.copy()]
    for step in range(1, steps + 1):
        task2.msd_kernel(old, current, new)
        old, current, new = current, new, old
        if step % every == 0:
            frames.append(current.copy())
    return np.array(frames).reshape(len(frames), -1, 3)


shape = (8, 8, 8)
with course.attempt():
    frames = drop(shape, 1200, 10)
    fig, ax = plt.subplots(figsize=(7, 3.5))
    steps = 10 * np.arange(len(frames))
    ax.plot(steps, np.ptp(frames[..., 1], axis=1), label="height of the grid")
    ax.plot(steps, frames[..., 1].min(axis=1), label="lowest particle")
    ax.set(xlabel="step", ylabel="y", title="A grid of axis springs lands")
    ax.legend()
    plt.show()
    print(viz.plot_in_words(ax))

# %%
with course.attempt():
    drawing = msd.Body.grid(shape, spacing=h, neighbours=(1,))  # its springs, for the colours
    movie = msd.Trajectory(drawing, dt, steps, steps * dt, frames, None, msd.EnergyLedger())
    if np.isfinite(frames).all():
        display(HTML(viz.to_html(movie, max_frames=31, up="y", view=(-30, 20), time_unit="units")))
    else:  # springs that put energy in: the grid flew apart, there is nothing to draw
        blown = steps[~np.isfinite(frames).all(axis=(1, 2))][0]
        print(f"the grid blew apart (positions not finite by step {blown}): the checks say why")

# %% [markdown]
# Until it lands the grid falls as one block: gravity accelerates every
# particle alike and no spring is strained. The landing squashes the soft
# jelly; with nothing to take energy out, the springs give it back and the
# grid bounces. What it does after that depends on details as small as
# rounding: a lattice of axis springs resists stretching along its axes but
# not shearing, which is the subject of task 3.
#
# ## Check your answer

# %%
report = course.check(2)
