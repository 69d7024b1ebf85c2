# %% [markdown]
# # Task 1: the template's falling grid
#
# > *Provide an overview of the template code, in particular the `msd_kernel`.*
#
# The template is a crude particle system: a cube of $N \times N \times N$
# particles ($N = 20$) lifted above the floor $y = 0$ falls under a constant
# acceleration $\mathbf{a} = (0, {{ g }}, 0)$ with a time step $\Delta t = 0.1$.
# The original ran one GPU thread per particle; `task1.py` holds the same code
# in numpy (`initial_grid`, `msd_kernel`, `run_template`) and the questions,
# which you answer as short functions. `msdlab check 1` grades them.
#
# This notebook calls the functions of your task file (`assignments/task1.py`
# in a student's folder). A function you have not written yet prints what to
# do instead of a traceback: write it, save the file and run the cell again.

# %%
import inspect

import matplotlib.pyplot as plt
import numpy as np
from IPython.display import HTML

import msdlab as msd
from msdlab import viz
from msdlab.course.notebook import Course

course = Course()  # your assignments/ (MSDLAB_IMPL=solutions: the reference answers)
task1 = course.task(1)
print(f"task files: {course.label}")

# %% [markdown]
# ## The template
#
# Particle $(i, j, k)$ starts at $(-1, {{ y0 }}, -1) + h\,(i, j, k)$ with spacing
# $h = 2/N$; three position buffers (old, current, new) rotate after every
# step, and old = current at the start, so the grid starts at rest. This is
# the kernel every particle runs:

# %%
print(inspect.getsource(task1.msd_kernel))

# %%
# NBVAL_CHECK_OUTPUT
grid = task1.initial_grid()
print("grid shape:", grid.shape, " spacing h =", task1.SPACING)
for axis, name in enumerate("xyz"):
    print(f"{name} from {grid[..., axis].min():.2f} to {grid[..., axis].max():.2f}")

# %% [markdown]
# Run the template until every particle has landed and follow the mean height of
# the bottom and the top layer of particles:

# %%
old, current = grid.copy(), grid.copy()
new = np.empty_like(grid)
layers, first_clamped = [], None
while current[..., 1].max() > task1.FLOOR and len(layers) < 5000:
    task1.msd_kernel(old, current, new)
    old, current, new = current, new, old
    layers.append((current[:, 0, :, 1].mean(), current[:, -1, :, 1].mean()))
    if first_clamped is None and current[..., 1].min() <= task1.FLOOR:
        first_clamped = len(layers)
landed = len(layers)  # the steps until the top layer is on the floor too

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(np.arange(1, landed + 1), layers, label=["bottom layer", "top layer"])
ax.axhline(task1.FLOOR, color="k", lw=0.8, label="floor")
ax.set(xlabel="step", ylabel="height y", title="The template's grid falls and lands")
ax.legend()
plt.show()
print(viz.plot_in_words(ax))

# %% [markdown]
# ## Your answers
#
# **How many particles** does the template simulate with $N$ per edge?

# %%
# NBVAL_CHECK_OUTPUT
with course.attempt():
    print("N = 20:", task1.particle_count(20), "particles;  N = 30:", task1.particle_count(30))

# %% [markdown]
# **Which integration scheme is `msd_kernel`?** It computes a velocity from
# the last two positions, accelerates it, and moves. Put the first two lines
# into the third and compare with the brief's eq. (1.3),
#
# $$\mathbf{x}_i(t+\Delta t) = 2\,\mathbf{x}_i(t) - \mathbf{x}_i(t-\Delta t)
#   + \mathbf{a}_i(t)\,\Delta t^2. \tag{1.3}$$
#
# `integration_scheme()` returns one of `task1.SCHEMES`; `verlet_step` writes
# the kernel's new positions in the form of eq. (1.3). Here it is compared
# with the kernel on random positions far above the floor:

# %%
# NBVAL_CHECK_OUTPUT
rng = np.random.default_rng(1)
before, now = 5 + rng.random((50, 3)), 5 + rng.random((50, 3))
kernel = np.empty_like(now)
task1.msd_kernel(before, now, kernel)
with course.attempt():
    print("the kernel is:", task1.integration_scheme())
with course.attempt():
    same = np.allclose(task1.verlet_step(before, now, task1.DT, task1.GRAVITY), kernel)
    print("verlet_step gives the kernel's positions:", same)

# %% [markdown]
# **Where is a particle after $n$ steps?** From rest, the template moves it by
# $g\,\Delta t^2$ in the first step, $2g\,\Delta t^2$ in the second, ...
# `height_after(n)` is compared with a single particle run by the template
# (floor left out: it starts at $y_0 = {{ y0 }}$, and the last $n$, the last hundred
# steps before the bottom layer lands, keeps it above the floor):

# %%
# NBVAL_CHECK_OUTPUT
counts = (1, 2, 10, 100, 100 * (first_clamped // 100))
with course.attempt():
    yours = [task1.height_after(steps) for steps in counts]
    print(f"{'steps':>5} {'yours':>10} {'template':>10}")
    for steps, height in zip(counts, yours):
        template = task1.run_template(steps, n=1)[0, 0, 0, 1]  # one particle, at y0
        print(f"{steps:>5} {height:>10.6f} {template:>10.6f}")

# %% [markdown]
# **After how many steps does the bottom layer reach the floor?** That is the
# first step whose new height, before the clamp, is at or below $y = 0$.

# %%
# NBVAL_CHECK_OUTPUT
print("the template's grid first touches the floor in step", first_clamped)
with course.attempt():
    print("steps_to_floor() =", task1.steps_to_floor())

# %% [markdown]
# ## The same run in the engine
#
# `msd.Verlet()` is eq. (1.3) with the template's three buffers, so the engine
# reproduces the template step for step: a body of the grid's particles, no
# springs, the template's gravity and a floor that clamps $y$.

# %%
# NBVAL_CHECK_OUTPUT
body = msd.Body.from_arrays(grid.reshape(-1, 3))
forces = [msd.Gravity(task1.GRAVITY), msd.Ground(task1.FLOOR)]
sim = msd.Simulation(body, msd.Verlet(), task1.DT, forces)
run = sim.run(steps=landed, record_every=25)
same = np.allclose(body.positions, current.reshape(-1, 3))
print(f"engine = template after {landed} steps:", same)
print(f"highest particle now at y = {body.positions[:, 1].max():.2f}")

# %% [markdown]
# Without springs nothing holds the particles together: each layer lands and
# stays where it hits the floor (no bounce, no friction), until the cube is a
# flat sheet.

# %%
HTML(viz.to_html(run, max_frames=35, up="y", view=(-30, 20), time_unit="s"))

# %% [markdown]
# ## Check your answers
#
# The checks of task 1 (what `msdlab check 1` runs), with what they saw:

# %%
report = course.check(1)
