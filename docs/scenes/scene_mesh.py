"""
Mesh
====

A 10×10 square mesh with both diagonals (342 springs).

`msdlab.scenes.gallery.mesh`: Springs 4: a square mesh with both diagonals in every cell
(342 springs for 10×10).

A scene of the 2-D springs gallery, in pixels and animation frames; ``--set model=frame``
runs the page's own per-frame update.

From the command line: ``msdlab run mesh --save mesh.gif``.
"""

# %%
# Build the scene and run it for the first half of its default duration
# (300 of 600 frames), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("mesh")
sim = scene.build()
steps = round(300 / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "mesh.gif", max_frames=30, dpi=50)
