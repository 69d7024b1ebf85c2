"""
Cloth
=====

A 10×10 cloth over 10 m × 8 m at z = 10 m, pinned at two corners, damped by λ.

`msdlab.scenes.cloth.cloth`: A ``nodes`` mesh over [0, extent_x]×[0, extent_y] at z =
``height`` (m), top edge pinned.

``msdlab run cloth --integrator explicit-euler`` blows up at this step, and says why.

From the command line: ``msdlab run cloth --save cloth.gif``.
"""

# %%
# Build the scene and run it for its default duration
# (10 s), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("cloth")
sim = scene.build()
steps = round(scene.duration / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "cloth.gif", max_frames=30, dpi=50)
