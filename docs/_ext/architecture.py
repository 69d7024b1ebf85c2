"""Draws the architecture picture of the engine page at build time (matplotlib, offline).

The layers are those `tests/architecture/test_imports.py` reads from the folders: a module
imports only its own layer and the layers below it.
"""

from __future__ import annotations

from pathlib import Path

# (layer, what it holds), lowest first
LAYERS = [
    (
        "engine",
        "equations · model (body, springs, forces) · backends: contract, layout, numpy | numba\n"
        "dynamics · integrators · simulation: stepping, the energy ledger, stability",
    ),
    ("analysis · interaction", "measured stable dt, convergence · ground, walls, grab"),
    ("msdlab", "the package: the public names of the layers below (import msdlab as msd)"),
    ("scenes · course", "ready simulations · task loading, checks' feedback, pytest plugin"),
    ("viz", "pictures, animations, the live view"),
    ("instructor", "templates, release, grading, sandbox, Gradescope, validate"),
    ("commands", "msdlab demo, scenes, run, check, grade, ..."),
    ("cli · jupyter_extension", "the ways in: the msdlab command, the Jupyter server's side"),
]


def draw(path: Path) -> None:
    """The layers as a stack of boxes, lowest at the bottom, arrows for "imports"."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import FancyBboxPatch

    gap, line = 0.35, 0.3
    figure, ax = plt.subplots(figsize=(7.2, 5.8))
    colours = plt.get_cmap("Blues")
    y = 0.0
    for level, (name, holds) in enumerate(LAYERS):
        height = 0.6 + line * (holds.count("\n") + 1)
        if level:
            ax.annotate(
                "",
                xy=(9.4, y - gap + 0.02),
                xytext=(9.4, y - 0.02),
                arrowprops={"arrowstyle": "-|>", "color": "#1f4e79"},
            )
        ax.add_patch(
            FancyBboxPatch(
                (0.0, y),
                10.0,
                height,
                boxstyle="round,pad=0.02,rounding_size=0.12",
                facecolor=colours(0.15 + 0.1 * (len(LAYERS) - level) / len(LAYERS)),
                edgecolor="#1f4e79",
            )
        )
        ax.text(0.25, y + height - 0.28, name, fontsize=12, weight="bold", va="center")
        ax.text(0.25, y + 0.15, holds, fontsize=9, va="bottom", color="#222222", linespacing=1.4)
        y += height + gap
    first = 0.6 + line * (LAYERS[0][1].count("\n") + 1)  # the lowest box's height
    ax.text(9.55, first + gap / 2, "imports", fontsize=8, va="center", color="#1f4e79")
    top = y
    ax.set_xlim(-0.1, 10.1)
    ax.set_ylim(-0.1, top - gap + 0.1)
    ax.axis("off")
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, format="svg", metadata={"Date": None})
    plt.close(figure)


def setup(app) -> dict[str, bool]:
    def generate(app) -> None:
        draw(Path(app.srcdir) / "_generated" / "architecture.svg")

    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True}
