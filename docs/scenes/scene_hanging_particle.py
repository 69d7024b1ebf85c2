"""
Hanging particle
================

A particle hanging from a fixed one.

`msdlab.scenes.gallery.hanging_particle`: One fixed particle at (300, 150) (page) holding
another 100 px below it.

A scene of the 2-D springs gallery, in pixels and animation frames; ``--set model=frame``
runs the page's own per-frame update.

From the command line: ``msdlab run hanging-particle --save hanging-particle.gif``.
"""

# %%
# Build the scene and run it for its default duration
# (600 frames), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("hanging-particle")
sim = scene.build()
steps = round(scene.duration / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "hanging-particle.gif", max_frames=30, dpi=50)
