"""
Truss
=====

A narrow braced truss (a worm) on the floor.

`msdlab.scenes.gallery.truss`: Springs 6: a narrow truss (a "worm") of ``segments`` braced
cells, dropped on the floor.

A scene of the 2-D springs gallery, in pixels and animation frames; ``--set model=frame``
runs the page's own per-frame update.

From the command line: ``msdlab run truss --save truss.gif``.
"""

# %%
# Build the scene and run it for the first half of its default duration
# (300 of 600 frames), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("truss")
sim = scene.build()
steps = round(300 / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "truss.gif", max_frames=30, dpi=50)
