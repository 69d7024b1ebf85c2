r"""
Jelly cube
==========

The brief's 20³ grid, rotated 58.3°, 26 neighbours, damped Verlet, lands on the floor.

`msdlab.scenes.jelly.jelly_cube`: A ``size``\ ³ jelly cube rotated by ``angle`` degrees about
``axis``, above the floor y = 0.

The gallery drops a 10³ cube (the scene's default is the brief's 20³) so that the page
builds quickly; ``--set size=20`` gives the brief's.

From the command line: ``msdlab run jelly-cube --set size=10 --save jelly-cube.gif``.
"""

# %%
# Build the scene and run it for its default duration
# (600 s), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("jelly-cube")
sim = scene.build(size=10)
steps = round(scene.duration / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring drawn by its strain (line and colour).
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "jelly-cube.gif", max_frames=30, dpi=50)
