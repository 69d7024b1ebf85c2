"""
Driven mesh
===========

The mesh hanging from a particle moved by sine + noise.

`msdlab.scenes.gallery.driven_mesh`: Springs 5: the mesh hanging from its top-middle
particle, which a driver moves.

A scene of the 2-D springs gallery, in pixels and animation frames; ``--set model=frame``
runs the page's own per-frame update.

From the command line: ``msdlab run driven-mesh --save driven-mesh.gif``.
"""

# %%
# Build the scene and run it for its default duration
# (600 frames), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("driven-mesh")
sim = scene.build()
steps = round(scene.duration / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "driven-mesh.gif", max_frames=30, dpi=50)
