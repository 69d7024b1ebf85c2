# %% [markdown]
# # A hanging cloth
#
# A course-project notebook ("Mass Spring Model") proposed a cloth as a mesh of
# nodes joined by edges, with the force on each node
#
# $$\mathbf{F} = m\mathbf{g} + \sum_{\text{springs}} k\,(\ell - \ell_{\text{rest}})\,
#   \hat{\mathbf{e}}, \qquad \frac{d\mathbf{x}}{dt} = \mathbf{v}, \qquad
# \frac{d\mathbf{v}}{dt} = \frac{\mathbf{F} - \lambda\mathbf{v}}{m},$$
#
# $\mathbf{g} = (0, 0, -9.8)$ m/s², zero initial velocity, a 10×10 mesh over
# $x \in [0, 10]$, $y \in [0, 8]$ at height $z = 10$, stepped with Euler's
# method. Its code never ran: undefined names, gravity pointing up in a later
# version, inputs updated in place. The scene `msdlab.scenes.cloth` is a working
# version: the top edge ($y = 8$) pinned at its corners (or along the whole
# row), nodes of 0.1 kg, edges of $k = 100$ N/m plus both diagonals of every
# cell (shear springs), $\lambda = 0.1$ N·s/m, $\Delta t = 0.01$ s.

# %%
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import HTML

import msdlab as msd
from msdlab import viz
from msdlab.scenes.cloth import cloth

# %% [markdown]
# ## It sags and comes to rest

# %%
sim = cloth()
start = sim.body.positions.copy()
run = sim.run(duration=10.0, record_every=20)
HTML(viz.to_html(run, max_frames=30, view=(-30, 20)))

# %%
# NBVAL_CHECK_OUTPUT
x = sim.body.positions
print(f"pins held: {np.array_equal(x[sim.body.fixed], start[sim.body.fixed])}")
print(f"lowest point after 10 s: z = {x[:, 2].min():.2f} m")
ledger = run.energies
print(f"energy {ledger.total[0]:.0f} J at the start, {ledger.total[-1]:.0f} J after 10 s")
print(f"taken out by λ: {ledger.dissipated['viscous'][-1]:.0f} J")

# %%
figure = viz.plot_energy(ledger)
plt.show()
print(viz.plot_in_words(figure))

# %% [markdown]
# ## Pinned along the top row, and without shear springs
#
# Pinned along its whole top edge, the cloth hangs like a curtain. With the
# notebook's mesh of edges only (`shear=False`), nothing resists shearing the
# squares: they shear into thin rhombi, the cloth narrows between its pins and
# hangs lower.

# %%
# NBVAL_CHECK_OUTPUT
variants = {"corners": cloth(), "row": cloth(pin="row"), "edges only": cloth(shear=False)}
for sim in variants.values():
    sim.run(duration=10.0, record_every=100)
for name in ("corners", "row"):
    print(f"pinned ({name}): lowest point z = {variants[name].body.positions[:, 2].min():.2f} m")

# %%
fig = plt.figure(figsize=(15, 4.5), layout="constrained")
for place, (name, sim) in enumerate(variants.items(), 1):
    ax = fig.add_subplot(1, 3, place, projection="3d")
    viz.plot_body(sim.body, ax=ax, view=(-30, 20), title=name)
plt.show()
for name, sim in variants.items():
    print(viz.body_in_words(sim.body, up=2, title=name))

# %% [markdown]
# ## Which Euler?
#
# The notebook's loop was `v += h*f; x += h*v`: the position moves with the
# *new* velocity. That is symplectic (semi-implicit) Euler, the scene's default,
# stable for $\Delta t < 2/\omega_{\max}$. Textbook forward Euler takes both
# updates from the old state. For a mode $\ddot x = -\omega^2 x - \gamma\dot x$
# (here $\gamma = \lambda/m = 1$/s) its amplification per step is
# $|1 + s\,\Delta t|$ with $s = -\gamma/2 \pm i\sqrt{\omega^2 - \gamma^2/4}$, at
# most 1 only while
#
# $$\Delta t \le \gamma/\omega^2 :$$
#
# the damping has to beat the stiffness in every mode.

# %%
# NBVAL_CHECK_OUTPUT
sim = cloth()
omega = msd.stiffest_mode(sim.body, sim.forces).omega
print(f"stiffest mode: ω = {omega:.1f} rad/s")
for integrator in (msd.SymplecticEuler(), msd.ExplicitEuler()):
    limit = msd.max_stable_dt(sim.body, integrator, sim.forces)
    print(f"{type(integrator).__name__:<15} largest stable dt {limit:.2g} s")
print(f"γ/ω² = {1.0 / omega**2:.2g} s")

# %% [markdown]
# At the notebook's $\Delta t = 0.01$ s forward Euler is 85 times over its
# limit. The engine stops in the step where the state stops being
# believable and says why, instead of returning NaN:

# %%
sim = cloth(integrator=msd.ExplicitEuler())
try:
    sim.run(duration=10.0, record_every=10)
except msd.SimulationDiverged as error:
    blowup = error
    print(error)

# %%
# NBVAL_CHECK_OUTPUT
print(f"forward Euler blew up within the first second: {blowup.time < 1.0}")
print(f"the last state kept is finite: {np.all(np.isfinite(sim.body.positions))}")

# %% [markdown]
# Below its limit forward Euler is stable, but it needs 85 times more steps
# for the same simulated time:

# %%
# NBVAL_CHECK_OUTPUT
sim = cloth(integrator=msd.ExplicitEuler())
sim.dt = 0.8 * msd.max_stable_dt(sim.body, msd.ExplicitEuler(), sim.forces)
run = sim.run(steps=3000, record_every=500)
print(f"3000 steps of {sim.dt:.2g} s cover {sim.time:.2f} s and stay finite: ", end="")
print(np.all(np.isfinite(run.positions)))

# %% [markdown]
# ## Live: drag the cloth
#
# The cloth running live in the notebook: the browser draws it while Python
# steps it in real time in the background. Drag a particle with the left button;
# drag the empty space (or use the right button) to turn the view, the wheel to
# zoom. The sliders change the stiffness, the damping λ, gravity and $\Delta t$
# between two steps: raise $\Delta t$ past the limit above and the view stops
# with the engine's diagnosis. It works offline in JupyterLab and VS Code.

# %%
live = viz.show(cloth(), view=(-30, 20))
