# %% [markdown]
# # Task 4: neighbours at √2 and √3 spacings
#
# > *Include neighbors with rest length sqrt(2) and/or sqrt(3). Does this
# > improve the simulation results? How does this affect the speed of the
# > simulation?*
#
# Besides its 6 axis neighbours at distance $h$, a grid particle has 12 face
# diagonal neighbours at $h\sqrt2$ and 8 body diagonal ones at $h\sqrt3$: 26 in
# all. Neighbours are named by their squared distance in grid units, as in the
# brief: 1, 2, 3. You write `neighbour_offsets`, `grid_springs` (each spring
# once, rest length $h\sqrt{s}$ so that the grid at rest is free of stress),
# the experiment of task 3 with your springs (`drop_rotated_cube`) and a
# measurement of the cost of a step (`step_cost`). The same idea makes cloth
# hold its shape in graphics: structural, shear and bending springs (Provot 1995).

# %%
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import HTML, display

import msdlab as msd
from msdlab import viz
from msdlab.course.notebook import Course
from msdlab.engine.backends import numpy as kernels

course = Course()  # your assignments/ (MSDLAB_IMPL=solutions: the reference answers)
task4 = course.task(4)
print(f"task files: {course.label}")

# %% [markdown]
# ## Offsets and springs

# %%
# NBVAL_CHECK_OUTPUT
with course.attempt():
    for wanted in [(1,), (2,), (3,), (1, 2, 3)]:
        offsets = task4.neighbour_offsets(wanted)
        symmetric = {tuple(o) for o in offsets} == {tuple(-o) for o in offsets}
        print(f"squared distances {wanted}: {len(offsets)} offsets, o and -o both: {symmetric}")

# %% [markdown]
# On a $3 \times 3 \times 3$ grid the engine's `Body.grid` has the same springs.
# Yours must list each once, and at rest every spring must have its rest length.

# %%
# NBVAL_CHECK_OUTPUT
h = 0.5
positions = task4.grid_positions((3, 3, 3), h)
with course.attempt():
    for wanted in [(1,), (2,), (3,), (1, 2, 3)]:
        pairs, rest = task4.grid_springs((3, 3, 3), h, wanted)
        engine = msd.Body.grid((3, 3, 3), spacing=h, neighbours=wanted)
        once = len({tuple(sorted(p)) for p in pairs.tolist()}) == len(pairs)
        length = np.linalg.norm(positions[pairs[:, 0]] - positions[pairs[:, 1]], axis=1)
        kinds = ", ".join(f"{r:.4f}h" for r in sorted(set(np.round(rest / h, 4))))
        print(f"{wanted}: {len(pairs)} springs (engine {engine.n_springs}), each once: {once}")
        print(f"    rest lengths {kinds}, stress-free: {np.allclose(length, rest)}")

# %% [markdown]
# ## Does it improve the results?
#
# Count again the ways to deform a $4^3$ cube that cost no energy (zero
# eigenvalues of the stiffness matrix, 6 of which are rigid motions), now
# with your springs:

# %%
# NBVAL_CHECK_OUTPUT
grid = task4.grid_positions((4, 4, 4), h)
with course.attempt():
    for wanted in [(1,), (1, 2), (1, 3), (1, 2, 3)]:
        pairs, rest = task4.grid_springs((4, 4, 4), h, wanted)
        body = msd.Body.from_arrays(grid, pairs, rest_lengths=rest)
        jx, _ = kernels.spring_jacobians(body, grid)
        stiffness = np.linalg.eigvalsh(-jx.toarray())
        free = int(np.sum(stiffness < 1e-9 * stiffness.max()))
        print(f"{wanted}: {len(pairs)} springs, {free - 6} ways to fold without resistance")

# %% [markdown]
# With the face diagonals the lattice is rigid; with the body diagonals alone a
# few ways to fold remain. The drop experiment of task 3, with your springs:

# %%
# NBVAL_CHECK_OUTPUT
with course.attempt():
    for angle, axis in [(30, (0, 0, 1)), (30, (1, 0, 1)), (58.3, (1, 1, 1))]:
        for wanted in [(1,), (1, 2, 3)]:
            ratio = task4.drop_rotated_cube(angle, axis, wanted)
            fate = "kept its shape" if ratio > 0.9 else "folded flat" if ratio < 0.1 else "bent"
            print(f"axis {axis} {angle:>4}°, {wanted!s:<9}: flatness ratio {ratio:.1f}, {fate}")

# %% [markdown]
# A tilted $4^3$ jelly with your 26-neighbour springs, under the template's
# gravity and floor (spacing $2/4$, $k = 0.5$, no damping):

# %%
with course.attempt():
    pairs, rest = task4.grid_springs((4, 4, 4), 0.5)
    jelly = msd.Body.from_arrays(
        task4.grid_positions((4, 4, 4), 0.5) + (0, 1.0, 0), pairs, stiffness=0.5, rest_lengths=rest
    )
    jelly.rotate(msd.rotation_matrix(30, (1, 0, 1)))
    forces = [msd.Gravity(task4.GRAVITY), msd.Ground(0.0)]
    run = msd.Simulation(jelly, msd.Verlet(), task4.DT, forces).run(steps=2000, record_every=50)
    display(HTML(viz.to_html(run, max_frames=41, up="y", view=(-30, 20), time_unit="units")))

# %% [markdown]
# ## What does it cost?
#
# A step evaluates every spring once, so its cost grows with the number of
# springs: an interior particle has 3 springs of its own with axis neighbours
# only, 13 with all 26.

# %%
# NBVAL_CHECK_OUTPUT
with course.attempt():
    for wanted in [(1,), (1, 2, 3)]:
        pairs, _ = task4.grid_springs((20, 20, 20), 0.1, wanted)
        print(f"20³ grid, {wanted}: {len(pairs)} springs, {len(pairs) / 8000:.2f} per particle")

# %% [markdown]
# Timings depend on the machine (this cell's output is not compared by the tests).
# A first step compiles the kernel, and a large body (from 50 000 springs) runs on
# all the processor's cores, with a kernel of its own: each setting runs a few
# steps before it is timed.


# %%
def warm_cost(n: int, wanted: tuple) -> tuple[int, float]:
    """`step_cost` of 30 steps, after 3 untimed ones (compiling is not a step's cost)."""
    task4.step_cost(n, wanted, steps=3)
    return task4.step_cost(n, wanted, steps=30)


with course.attempt():
    sizes = (6, 10, 14, 18)
    costs = {wanted: [warm_cost(n, wanted) for n in sizes] for wanted in [(1,), (1, 2, 3)]}
    fig, ax = plt.subplots(figsize=(6, 3.5))
    for wanted, points in costs.items():
        springs, seconds = np.array(points).T
        ax.plot(springs, seconds * 1e3, "o-", label=f"neighbours {wanted}")
    for n, few, many in zip(sizes, *costs.values()):
        print(
            f"n = {n}: (1, 2, 3) has {many[0] / few[0]:.1f}× the springs of (1,), "
            f"{many[1] / few[1]:.1f}× the time a step"
        )
    ax.set(xlabel="springs", ylabel="ms per step", title="Cost of a step")
    ax.legend()
    plt.show()
    print(viz.plot_in_words(ax))

# %% [markdown]
# There is a second cost. More springs make the lattice stiffer: its highest
# vibration frequency $\omega_{\max}$ rises, and the largest stable time step,
# $2/\omega_{\max}$ for Verlet, falls. For the same $k$:

# %%
# NBVAL_CHECK_OUTPUT
for wanted in [(1,), (1, 2, 3)]:
    body = msd.Body.grid((10, 10, 10), spacing=0.2, stiffness=0.5, neighbours=wanted)
    print(f"{wanted}: largest stable dt {msd.max_stable_dt(body, msd.Verlet()):.3f}")

# %% [markdown]
# So the 26-neighbour jelly holds its shape at any tilt, for about four times
# the work per step and half the time step.
#
# ## Check your answers

# %%
report = course.check(4)
