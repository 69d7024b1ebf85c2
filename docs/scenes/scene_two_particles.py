"""
Two particles
=============

Two particles and one spring, pulled apart.

`msdlab.scenes.gallery.two_particles`: Springs 1: two particles 100 px apart, the right one
pulled ``pull`` px further out.

A scene of the 2-D springs gallery, in pixels and animation frames; ``--set model=frame``
runs the page's own per-frame update.

From the command line: ``msdlab run two-particles --save two-particles.gif``.
"""

# %%
# Build the scene and run it for its default duration
# (600 frames), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("two-particles")
sim = scene.build()
steps = round(scene.duration / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "two-particles.gif", max_frames=30, dpi=50)
