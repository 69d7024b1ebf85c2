# %% [markdown]
# # A tour of msdlab: the engine in ten minutes
#
# A mass-spring-damper model describes a body as particles joined by springs.
# Every particle obeys Newton's second law,
#
# $$m_i \ddot{\mathbf{x}}_i = \sum_j \mathbf{f}_{ij} + \mathbf{F}^{\text{ext}}_i, \qquad
# \mathbf{f}_{ij} = k\,(l_{ij} - \lVert\mathbf{x}_i - \mathbf{x}_j\rVert)\,
# \frac{\mathbf{x}_i - \mathbf{x}_j}{\lVert\mathbf{x}_i - \mathbf{x}_j\rVert},$$
#
# and an integrator steps all of them forward by a time step $\Delta t$. This
# notebook builds one particle on a spring, then a body, steps it with an
# integrator, reads its energy ledger and animates it.
#
# Cells marked `# NBVAL_CHECK_OUTPUT` print key numbers that the test suite
# compares with the saved outputs (`pytest` runs every notebook with nbval).

# %%
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import HTML

import msdlab as msd
from msdlab import viz

# %% [markdown]
# ## A particle and a spring
#
# A fixed particle at the origin holds a 2 kg particle on a spring of
# stiffness $k = 10$ N/m. The spring's rest length is the distance at which it
# is made (1 m). Pulled out by 0.2 m and let go, the particle oscillates with
# $\omega = \sqrt{k/m}$, period $T = 2\pi\sqrt{m/k}$.

# %%
body = msd.Body()
anchor = body.add_particle(msd.Particle(position=(0, 0, 0), fixed=True))
bob = body.add_particle(msd.Particle(position=(1, 0, 0), mass=2.0))
index = body.add_spring(msd.Spring(anchor, bob, stiffness=10.0))
spring = body.springs[index]
body.particles[bob].position = (1.2, 0, 0)
print(body)
print(body.particles[bob])
print(spring)
print("force of the spring on the particle:", spring.force())

# %% [markdown]
# `Simulation` steps the body; `run` records frames. Velocity Verlet is a
# second-order, energy-conserving scheme. The period is read off the times at
# which the particle passes its rest position going outwards.

# %%
# NBVAL_CHECK_OUTPUT
sim = msd.Simulation(body, msd.VelocityVerlet(), dt=1e-3)
run = sim.run(duration=9.0)
stretch = run.positions[:, bob, 0] - 1.0
t = run.times
up = np.flatnonzero((stretch[:-1] < 0) & (stretch[1:] >= 0))
crossings = t[up] - stretch[up] * (t[up + 1] - t[up]) / (stretch[up + 1] - stretch[up])
print(f"period predicted 2π√(m/k) = {2 * np.pi * np.sqrt(2.0 / 10.0):.4f} s")
print(f"period measured           = {np.mean(np.diff(crossings)):.4f} s")
print(f"energy drift over 9 s: below 1e-5 of the energy: {run.energies.relative_drift() < 1e-5}")

# %%
fig, ax = plt.subplots(figsize=(7, 3))
ax.plot(t, stretch)
ax.set(xlabel="time (s)", ylabel="stretch (m)", title="One particle on a spring")
plt.show()
print(viz.plot_in_words(ax))

# %% [markdown]
# ## A body
#
# `Body.grid` builds a lattice: `neighbours=(1, 2, 3)` joins every particle to
# its axis neighbours (rest length = spacing), its face diagonals ($\sqrt2$) and
# body diagonals ($\sqrt3$): up to 26 springs per particle, a jelly cube.
# Positions, velocities and masses are numpy arrays that can be edited in place.

# %%
# NBVAL_CHECK_OUTPUT
cube = msd.Body.grid(
    (5, 5, 5), spacing=0.1, stiffness=200.0, neighbours=(1, 2, 3), origin=(0, 0.3, 0), mass=0.01
)
cube.rotate(msd.rotation_matrix(30, axis=(0, 0, 1)))  # tilted: it lands on an edge
print(cube)
print(f"lowest particle at y = {cube.positions[:, 1].min():.3f} m")
print(f"total mass {cube.masses.sum():g} kg")

# %% [markdown]
# ## An integrator and its time step
#
# Every explicit integrator has a largest stable time step set by the stiffest
# vibration mode $\omega_{\max}$ of the body: $2/\omega_{\max}$ for Verlet.
# `max_stable_dt` computes it; we step well below it. `Verlet(damping=λ)` is the
# brief's eq. (1.4): it keeps a fraction $(1-\lambda)$ of the velocity each step.

# %%
# NBVAL_CHECK_OUTPUT
print(f"predicted largest stable dt: {msd.max_stable_dt(cube, msd.Verlet()) * 1e3:.2f} ms")
sim = msd.Simulation(
    cube,
    msd.Verlet(damping=0.002),
    dt=1e-3,
    forces=[msd.Gravity((0, -9.81, 0)), msd.Ground(height=0.0)],
)
run = sim.run(duration=1.5, record_every=10)
size = np.ptp(cube.positions, axis=0)
print(f"after 1.5 s: lowest particle at y = {cube.positions[:, 1].min():.3f} m")
print(f"the cube kept its shape (every side 0.4 m ± 10 %): {np.allclose(size, 0.4, rtol=0.1)}")

# %% [markdown]
# ## The energy ledger
#
# Each recorded frame books the energy in the body (kinetic, elastic,
# gravitational) and the energy taken out so far by each mechanism: the Verlet
# damping (`integrator`), the inelastic ground (`ground`), dashpots. What is
# left over, the `drift`, is the integrator's own error.

# %%
print(run.energies.table())

# %%
figure = viz.plot_energy(run.energies)
plt.show()
print(viz.plot_in_words(figure))

# %% [markdown]
# ## Seeing it move
#
# `viz.to_html` makes an animation with play controls that runs in the browser
# (no ffmpeg needed); springs show strain: thick orange stretched, dashed blue squeezed.

# %%
HTML(viz.to_html(run, max_frames=40, up="y", view=(-30, 20)))

# %% [markdown]
# ## Where next
#
# - `task1` … `task5`: the course's tasks, one notebook each, with their checks.
# - `scene_trampoline`, `scene_cloth`, `scene_gallery`: the worked examples of the
#   source documents, and where correct physics differs from what they saw.
# - `stability`: every integrator on one body, energy drift, the predicted and
#   measured largest stable time step, orders of convergence.
