# %% [markdown]
# # Task 3: tilt or rotate the initial layout
#
# > *Try to tilt or rotate the initial particle layout. Which implications does
# > this have for the simulation results?*
#
# You write a rotation (`rotation_matrix`, `rotate_layout`), the spring
# acceleration of eq. (1.1)-(1.2) for a body given as a list of springs, so
# that nothing in it depends on how the body is oriented
# (`spring_acceleration`), and the experiment: drop a rotated cube held by
# axis springs only and measure how flat it gets (`drop_rotated_cube`).
#
# A right-handed rotation by $\theta$ about the unit axis $\mathbf{n}$ is
# Rodrigues' formula
#
# $$R = \cos\theta\, I + \sin\theta\, [\mathbf{n}]_\times + (1 - \cos\theta)\,
#   \mathbf{n}\mathbf{n}^\mathsf{T}, \qquad
#   [\mathbf{n}]_\times = \begin{pmatrix} 0 & -n_z & n_y \\ n_z & 0 & -n_x \\
#   -n_y & n_x & 0 \end{pmatrix}.$$

# %%
import numpy as np
from IPython.display import HTML, display

import msdlab as msd
from msdlab import viz
from msdlab.course.notebook import Course
from msdlab.engine.backends import numpy as kernels
from msdlab.scenes import jelly

course = Course()  # your assignments/ (MSDLAB_IMPL=solutions: the reference answers)
task3 = course.task(3)
print(f"task files: {course.label}")

# %% [markdown]
# ## Rotations
#
# A quarter turn about $z$ takes $x$ to $y$. Every rotation matrix is
# orthogonal with determinant $+1$ and leaves its own axis where it is.

# %%
# NBVAL_CHECK_OUTPUT
with course.attempt():
    print(np.round(task3.rotation_matrix(90, (0, 0, 1)), 6) + 0.0)
    axis = np.array([1.0, 2.0, 2.0])
    R = task3.rotation_matrix(58.3, axis)
    print("orthogonal:", np.allclose(R.T @ R, np.eye(3)))
    print("determinant +1:", np.isclose(np.linalg.det(R), 1.0))
    print("keeps its axis:", np.allclose(R @ axis, axis))

# %%
# NBVAL_CHECK_OUTPUT
cube = msd.Body.grid((4, 4, 4), spacing=0.5, neighbours=(1, 2, 3))
springs = cube.edges()  # the grid's springs as a list: ends a, b and their values
with course.attempt():
    turned = task3.rotate_layout(cube.positions, 30, (1, 1, 0))
    moved = turned.mean(axis=0) - cube.positions.mean(axis=0)
    print("the centroid stays:", np.allclose(moved, 0))
    lengths = np.linalg.norm(turned[springs.a] - turned[springs.b], axis=1)
    print("every distance stays:", np.allclose(lengths, springs.rest_lengths))

# %% [markdown]
# ## Forces that do not care about orientation
#
# `spring_acceleration(positions, springs, rest_lengths, stiffness)` works on
# a list of springs $(i, j)$, so the same code serves any layout. Three things
# it must get right: the engine's numbers on a deformed body, equal and
# opposite forces (they add up to zero), and rotation: rotating the body
# rotates every force with it, $\mathbf{a}(R\mathbf{x}) = R\,\mathbf{a}(\mathbf{x})$.

# %%
# NBVAL_CHECK_OUTPUT
rng = np.random.default_rng(3)
x = cube.positions + 0.05 * rng.standard_normal(cube.positions.shape)
pairs = np.column_stack([springs.a, springs.b])
expected = msd.Dynamics(cube).acceleration(x, np.zeros_like(x))  # stiffness 1
with course.attempt():
    a = task3.spring_acceleration(x, pairs, springs.rest_lengths, 1.0)
    print("same as the engine:", np.allclose(a, expected, atol=1e-12))
    print("forces add up to zero:", np.allclose(a.sum(axis=0), 0, atol=1e-12))
    R = msd.rotation_matrix(40, (1, 0, 1))
    turned = task3.spring_acceleration(x @ R.T, pairs, springs.rest_lengths, 1.0)
    print("a(Rx) = R a(x):", np.allclose(turned, a @ R.T, atol=1e-12))

# %% [markdown]
# ## The experiment
#
# `drop_rotated_cube(angle, axis)` drops a $4^3$ cube of axis springs, rotated
# and lifted just above the floor, for 1500 steps of the template, and returns
# its flatness after / before (1: kept its shape, 0: folded flat). Flatness is
# the smallest spread of the particles in any direction, so it does not
# depend on the orientation.

# %%
# NBVAL_CHECK_OUTPUT
cases = [(0, (0, 0, 1)), (10, (0, 0, 1)), (30, (0, 0, 1)), (30, (1, 0, 1))]
with course.attempt():
    for angle, axis in cases:
        ratio = task3.drop_rotated_cube(angle, axis)
        fate = "kept its shape" if ratio > 0.9 else "folded flat" if ratio < 0.1 else "bent"
        print(f"axis {axis}, {angle:>2}°: flatness ratio {ratio:.1f}, {fate}")

# %% [markdown]
# Here is the brief's cube (the engine's jelly-cube scene with axis springs
# only, no damping, $4^3$ particles), turned by your `rotate_layout`:

# %%
with course.attempt():
    sim = jelly.jelly_cube(size=4, angle=0, neighbours=(1,), damping=0.0, dt=0.1)
    sim.body.positions = task3.rotate_layout(sim.body.positions, 30, (0, 0, 1))
    run = sim.run(steps=2000, record_every=50)
    display(HTML(viz.to_html(run, max_frames=41, up="y", view=(-30, 20), time_unit="units")))

# %% [markdown]
# ## Why it folds: counting springs
#
# A spring only resists a change of its own length. An axis-spring cube stands
# upright because gravity pulls along its vertical springs; tilted, gravity
# pulls across the squares, and a square of four springs can shear into a
# rhombus without stretching any of them. Counting shows it (Maxwell): $n$
# particles in 3-D have $3n$ ways to move; each independent spring blocks one,
# and 6 are rigid motions (3 moves, 3 turns) that no spring can block. The
# zero eigenvalues of the stiffness matrix $K = -\partial\mathbf{F}/\partial\mathbf{x}$
# count the ways to deform the body that cost no energy:

# %%
# NBVAL_CHECK_OUTPUT
axis_springs = msd.Body.grid((4, 4, 4), spacing=0.5, neighbours=(1,))
jx, _ = kernels.spring_jacobians(axis_springs, axis_springs.positions)
stiffness = np.linalg.eigvalsh(-jx.toarray())
free = int(np.sum(stiffness < 1e-9 * stiffness.max()))
print(f"{len(axis_springs)} particles: {3 * len(axis_springs)} ways to move")
print(f"{axis_springs.n_springs} axis springs: {free} ways cost no energy, 6 of them rigid motions")
print(f"so {free - 6} ways to fold the cube that no spring resists")

# %% [markdown]
# The forces themselves are the same physics in any orientation, as the check
# above shows: the collapse is the lattice's, not the code's. Task 4 adds the
# missing springs.
#
# ## Check your answers

# %%
report = course.check(3)
