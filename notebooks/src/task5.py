# %% [markdown]
# # Task 5: Verlet integration with damping
#
# > *Replace the time integration code with a Verlet integration scheme
# > (equation (1.3)) and introduce damping (equation (1.4)). Does this change
# > the behavior of the simulation? Does it allow larger time steps?*
#
# $$\mathbf{x}_i(t+\Delta t) = 2\,\mathbf{x}_i(t) - \mathbf{x}_i(t-\Delta t)
#   + \mathbf{a}_i(t)\,\Delta t^2 \tag{1.3}$$
# $$\mathbf{x}_i(t+\Delta t) = (2-\lambda)\,\mathbf{x}_i(t) - (1-\lambda)\,
#   \mathbf{x}_i(t-\Delta t) + \mathbf{a}_i(t)\,\Delta t^2 \tag{1.4}$$
#
# Written as a displacement, eq. (1.4) is
# $\mathbf{x}_{n+1} - \mathbf{x}_n = (1-\lambda)(\mathbf{x}_n - \mathbf{x}_{n-1})
# + \mathbf{a}_n\Delta t^2$: each step keeps the fraction $1-\lambda$ of the
# velocity, so $0 \le \lambda < 1$. You write it as an engine integrator,
# `DampedVerlet(damping)`, whose `step(x, v, dt, dynamics)` recovers
# $\mathbf{x}(t-\Delta t) = \mathbf{x} - \mathbf{v}\Delta t$ like the template, and
# `measured_stable_dt(λ)`, the largest time step that keeps a jelly cube stable.

# %%
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import HTML, display

import msdlab as msd
from msdlab import viz
from msdlab.course.notebook import Course
from msdlab.scenes import jelly

course = Course()  # your assignments/ (MSDLAB_IMPL=solutions: the reference answers)
task5 = course.task(5)
template = course.task(1)  # its given code: the template's falling grid
print(f"task files: {course.label}")

# %% [markdown]
# ## λ = 0 is the template
#
# The template's kernel already is eq. (1.3) (task 1). So your integrator with
# $\lambda = 0$, stepping a grid of particles under the template's gravity and
# floor, must reproduce the template's positions exactly. And $\lambda$ outside
# $[0, 1)$ must be refused: $\lambda \ge 1$ flips or freezes the velocity every step.

# %%
# NBVAL_CHECK_OUTPUT
grid = template.initial_grid(6)
with course.attempt():
    body = msd.Body.from_arrays(grid.reshape(-1, 3))
    forces = [msd.Gravity(template.GRAVITY), msd.Ground(template.FLOOR)]
    msd.Simulation(body, task5.DampedVerlet(0.0), template.DT, forces).run(steps=700)
    same = np.allclose(body.positions, template.run_template(700, n=6).reshape(-1, 3), atol=1e-12)
    print("λ = 0 gives the template's positions after 700 steps:", same)
for wrong in (1.2, -0.1):
    with course.attempt():
        try:
            task5.DampedVerlet(wrong)
            print(f"λ = {wrong} accepted")
        except ValueError:
            print(f"λ = {wrong} refused")

# %% [markdown]
# ## Does damping change the behaviour?
#
# A $3^3$ jelly (`task5.jelly()`: 26 neighbours, $k = 0.5$, unit masses) is
# given a random kick and left alone for 400 steps of $\Delta t = 0.1$. The
# energy ledger books kinetic + elastic energy. (It measures the kinetic energy
# with the velocity the step stores, half a step behind the positions, so even
# $\lambda = 0$ shows a wobble of about 1 %, not a loss.)

# %%
# NBVAL_CHECK_OUTPUT
kick = 0.01 * np.random.default_rng(5).standard_normal((27, 3))


def kicked(damping: float) -> msd.EnergyLedger:
    """The energy ledger of 400 steps of the kicked jelly with your integrator."""
    cube = task5.jelly()
    cube.velocities = kick
    simulation = msd.Simulation(cube, task5.DampedVerlet(damping), 0.1)
    return simulation.run(steps=400, record_every=5).energies


with course.attempt():
    ledgers = {damping: kicked(damping) for damping in (0.0, 0.01, 0.05)}
    for damping, ledger in ledgers.items():
        ratio = ledger.total[-1] / ledger.total[0]
        print(f"λ = {damping:<4}: energy after 400 steps / at the start {ratio:.2f}")

# %%
with course.attempt():
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for damping, ledger in ledgers.items():
        ax.plot(ledger.times, ledger.total, label=f"λ = {damping}")
    ax.set(xlabel="time", ylabel="kinetic + elastic energy", title="Damping takes energy out")
    ax.legend()
    plt.show()
    print(viz.plot_in_words(ax))

# %% [markdown]
# Each step multiplies the velocity by $1-\lambda$, so after $n$ steps it is
# $(1-\lambda)^n \approx e^{-\lambda n}$: a decay rate of $\lambda/\Delta t$ per unit
# of time. The damping is set per *step*: the same $\lambda$ at half the time
# step damps twice as fast in time.
#
# ## Does it allow larger time steps?
#
# For one vibration mode of angular frequency $\omega$, eq. (1.4) reads
# $x_{n+1} = (2-\lambda-\omega^2\Delta t^2)\,x_n - (1-\lambda)\,x_{n-1}$. Its
# solutions $x_n = z^n$ have $z^2 - (2-\lambda-\omega^2\Delta t^2)\,z + (1-\lambda) = 0$,
# and they stay bounded while both roots have $|z| \le 1$, which holds for
#
# $$\omega^2\Delta t^2 \le 4 - 2\lambda, \qquad
#   \Delta t_{\max} = \frac{\sqrt{4-2\lambda}}{\omega}.$$
#
# The engine computes this for any integrator (yours included) from the
# stiffest mode of the body (`msd.max_stable_dt`); `measured_stable_dt`
# bisects the time step at which a slightly kicked jelly blows up within 1000 steps.

# %%
# NBVAL_CHECK_OUTPUT
omega = msd.stiffest_mode(task5.jelly()).omega
print(f"stiffest mode of the 3³ jelly: ω = {omega:.4f}")
print(f"{'λ':>5} {'√(4-2λ)/ω':>10} {'predicted':>10} {'measured / predicted':>21}")
with course.attempt():
    for damping in (0.0, 0.01, 0.1, 0.5):
        predicted = msd.max_stable_dt(task5.jelly(), task5.DampedVerlet(damping))
        measured = task5.measured_stable_dt(damping)
        formula = np.sqrt(4 - 2 * damping) / omega
        print(f"{damping:>5} {formula:>10.3f} {predicted:>10.3f} {measured / predicted:>21.2f}")

# %% [markdown]
# So no: damping does not allow larger time steps. The limit $\sqrt{4-2\lambda}/\omega$
# *shrinks* as $\lambda$ grows: by 0.25 % at $\lambda = 0.01$, by 13 % at
# $\lambda = 0.5$. (The measured steps lie a little above the prediction
# because just past the limit a mode grows so slowly that 1000 steps from a
# small kick do not yet blow it up.) What damping does is take out the energy
# that otherwise keeps the jelly wobbling, and with it the jitter and the
# energy a clamping floor injects: runs look calmer, which is easy to mistake
# for stability. In the stability notebook, forward Euler is the scheme for
# which damping *does* enlarge the stable step.
#
# ## The jelly cube with your integrator
#
# The brief's flagship: the rotated cube with 26 neighbours landing on the
# floor (the engine's `jelly-cube` scene, here $6^3$ particles, $\Delta t = 0.4$),
# once without and once with damping.


# %%
# NBVAL_CHECK_OUTPUT
def landing(damping: float) -> msd.Trajectory:
    """1500 steps of the 6³ jelly-cube scene with your integrator."""
    sim = jelly.jelly_cube(size=6, integrator=task5.DampedVerlet(damping))
    return sim.run(steps=1500, record_every=15)


with course.attempt():
    runs = {damping: landing(damping) for damping in (0.0, 0.01)}
    for damping, run in runs.items():
        still = run.energies.kinetic[-1] < 1e-4
        print(f"λ = {damping:<4}: at rest on the floor after 1500 steps: {still}")

# %%
with course.attempt():
    fig, ax = plt.subplots(figsize=(7, 3.5))
    for damping, run in runs.items():
        ax.plot(run.times, np.ptp(run.positions[..., 1], axis=1), label=f"λ = {damping}")
    ax.set(xlabel="time", ylabel="height of the cube", title="Landing, with and without damping")
    ax.legend()
    plt.show()
    print(viz.plot_in_words(ax))
    display(HTML(viz.to_html(runs[0.01], max_frames=41, up="y", view=(-30, 20), time_unit="units")))

# %% [markdown]
# ## Check your answers

# %%
report = course.check(5)
