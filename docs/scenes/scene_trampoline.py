r"""
Trampoline
==========

A 1 kg ball dropped on a pre-tensioned 7×7 net with a fixed rim (--experiments).

`msdlab.scenes.trampoline.trampoline`: A ball (the last particle, `BALL`) over a
``size``\ ×\ ``size`` net with spacing 1 m, z up.

``msdlab run trampoline --experiments`` runs the report's seven experiments and prints their
outcomes as a table.

From the command line: ``msdlab run trampoline --save trampoline.gif``.
"""

# %%
# Build the scene and run it for the first half of its default duration
# (2.5 of 5 s), keeping about 30 frames.
from msdlab import viz
from msdlab.scenes import get_scene

scene = get_scene("trampoline")
sim = scene.build()
steps = round(2.5 / sim.dt)
run = sim.run(steps=steps, record_every=max(1, steps // 30))
print(run.energies.table(rows=5))

# %%
# The body at the end of the run, each spring coloured by its sag.
viz.plot_scene(scene, sim)

# %%
# The whole run as an animation.
viz.save_scene_animation(scene, sim, run, "trampoline.gif", max_frames=30, dpi=50)
