"""Draw the site's picture of a jelly cube, ``docs/_static/jelly.png`` (also the README's,
the site's logo and its favicon), from the root of the checkout::

    python docs/pictures.py            # or: python docs/pictures.py OUT.png

A 6³ jelly cube with axis and face-diagonal springs drops onto the floor; the picture is
the moment it is squashed most: its upright springs squeezed, its level ones stretched.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib
import numpy as np

import msdlab as msd
from msdlab import viz

PICTURE = Path(__file__).resolve().parent / "_static" / "jelly.png"


def squashed_cube() -> tuple[msd.Body, np.ndarray]:
    """The cube and its positions (m) when its height is least after landing."""
    body = msd.Body.grid((6, 6, 6), spacing=0.4, stiffness=600.0, neighbours=(1, 2))
    body.positions += (-1.0, 0.6, -1.0)
    forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground(0.0)]
    run = msd.Simulation(body, msd.Verlet(0.002), 5e-4, forces).run(steps=1400, record_every=10)
    heights = np.ptp(run.positions[..., 1], axis=1)
    return body, run.positions[int(np.argmin(heights))]


def main(path: Path = PICTURE) -> str:
    """Draw the picture at ``path``; its words (`viz.body_in_words`)."""
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    body, positions = squashed_cube()
    figure = viz.plot_body(body, positions, view=(-60, 20), up="y")
    figure.set_size_inches(4.8, 4.0)
    figure.savefig(path, dpi=80)
    plt.close(figure)
    return viz.body_in_words(body, positions, title="The squashed jelly cube")


if __name__ == "__main__":
    print(main(Path(sys.argv[1]) if len(sys.argv) > 1 else PICTURE))
