"""
Rope
====

18 particles, the first fixed, swinging down under gravity.

`msdlab.scenes.gallery.rope`: Springs 2: ``count`` particles in a horizontal line from a
fixed one at the top middle (300, 20) (page); it swings down and hangs inside the canvas: 17
links of 12 px plus Hooke's stretch Σ i·m g/K = 153 px put the end 357 px below the top one.

A scene of the 2-D springs gallery, in pixels and animation frames; ``--set model=frame``
runs the page's own per-frame update.

From the command line: ``msdlab run rope --save rope.gif``.
"""

# %%
# Build the scene and run it for its default duration
# (600 frames), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("rope")
sim = scene.build()
steps = round(scene.duration / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "rope.gif", max_frames=30, dpi=50)
