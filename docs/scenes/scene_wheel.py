"""
Wheel
=====

A ring of particles with spokes to a hub, bouncing.

`msdlab.scenes.gallery.wheel`: Springs 3: a ring of ``spokes`` particles, each joined to its
neighbours and to a hub.

A scene of the 2-D springs gallery, in pixels and animation frames; ``--set model=frame``
runs the page's own per-frame update.

From the command line: ``msdlab run wheel --save wheel.gif``.
"""

# %%
# Build the scene and run it for its default duration
# (600 frames), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("wheel")
sim = scene.build()
steps = round(scene.duration / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "wheel.gif", max_frames=30, dpi=50)
