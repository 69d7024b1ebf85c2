"""Drawing one body on matplotlib axes: springs drawn by strain, particles as dots.

`BodyView` owns the artists and redraws them for new positions, so static
plots, animations and the interactive window share one drawing. 3-D views take
the report's (MATLAB) angles: azimuth in the xy-plane from the -y axis,
elevation above the xy-plane; ``up`` names the vertical axis ("y" for the
brief's cube, whose floor is y = 0), by default the one `upright` finds.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from matplotlib.ticker import MaxNLocator, NullLocator
from mpl_toolkits.mplot3d import proj3d

from .. import Body, Simulation
from ..engine.model.springs import EdgeSprings
from ..interaction import SphereContact
from .lines import SpringLines, SpringLines3D
from .strain_style import STRAIN_MAP, add_key
from .upright import UPS, resolve_up

COLOURINGS = ("strain", "sag")  # what the springs' colour shows
LIVE_STRAIN_LIMIT = 0.3  # strain drawn at full colour in live views: what a drag or fall reaches
BALL_COLOUR = "tab:green"  # not on the strain map of the springs
_U, _V = np.meshgrid(np.linspace(0, 2 * np.pi, 13), np.linspace(0, np.pi, 7))
_UNIT_SPHERE = np.stack([np.cos(_U) * np.sin(_V), np.sin(_U) * np.sin(_V), np.cos(_V)])


def strains(edges: EdgeSprings, positions: np.ndarray) -> np.ndarray:
    """Strain of each spring of ``edges`` (`Body.edges`) at ``positions`` (N, d):
    |x_a - x_b| / rest length - 1 (> 0 stretched, < 0 squeezed)."""
    d = positions[edges.a] - positions[edges.b]
    return np.sqrt(np.einsum("ij,ij->i", d, d)) / edges.rest_lengths - 1.0


def sags(edges: EdgeSprings, positions: np.ndarray, up: str, rim: float) -> np.ndarray:
    """Depth of each spring's middle (``edges``, `Body.edges`) below the height ``rim`` along
    the ``up`` axis (> 0 below)."""
    axis = UPS.index(up)
    middles = 0.5 * (positions[edges.a, axis] + positions[edges.b, axis])
    return rim - middles


def check_colour(colour: str, body: Body) -> None:
    """Raise ValueError unless springs of ``body`` can be coloured by ``colour``."""
    if colour not in COLOURINGS or (colour == "sag" and body.dim != 3):
        raise ValueError(
            f"cannot colour springs by {colour!r}; choose 'strain' (any body) or 'sag' (3-D)"
        )


def rim_height(body: Body, positions: np.ndarray, up: str) -> float:
    """The height a net sags from: its highest pinned particle's (or highest particle's)."""
    heights = positions[:, UPS.index(up)]
    return float(heights[body.fixed].max() if body.fixed.any() else heights.max())


def spheres_of(sim: Simulation) -> list[tuple[int, float]]:
    """(particle, radius) of every ball in ``sim`` (its `SphereContact` forces)."""
    return [(f.center, f.radius) for f in sim.forces if isinstance(f, SphereContact)]


def new_axes(
    body: Body, figure: Figure | None = None, size: float = 8.0, layout: str = "constrained"
) -> Axes:
    """Axes fit for ``body``: plain for 2-D, 3-D for 3-D, on a ``size`` inches wide figure
    (800 px at the default 100 dpi); ``layout`` "none" keeps the axes still between draws."""
    import matplotlib.pyplot as plt

    figure = figure or plt.figure(figsize=(size, size * 0.7), layout=layout)
    return figure.add_subplot(projection="3d" if body.dim == 3 else None)


class BodyView:
    """The artists drawing ``body`` on ``ax`` (2-D or 3-D axes), updated by `update`.

    ``colour`` "strain" draws springs by strain, ``strain_limit`` drawn at full
    colour (`strain_style`: blue, thin and dashed squeezed, orange and thick
    stretched), the key to the lines with the colour bar; "sag" (3-D) by their depth
    below the rim (the highest pinned particle), ``strain_limit`` then being the deepest colour, in
    length units: a net's sag shows from any view. ``view`` = (azimuth, elevation) in
    degrees, report convention;
    ``spheres`` are (particle, radius) pairs drawn as balls (see `spheres_of`).
    """

    def __init__(
        self,
        ax: Axes,
        body: Body,
        positions: np.ndarray | None = None,
        *,
        strain_limit: float | None = None,
        view: Sequence[float] | None = None,
        up: str | None = None,
        spheres: Sequence[tuple[int, float]] = (),
        colorbar: bool = True,
        colour: str = "strain",
    ) -> None:
        up = resolve_up(up, None, body.dim)
        if up not in UPS:
            raise ValueError(f"unknown vertical axis {up!r}; choose one of {', '.join(UPS)}")
        check_colour(colour, body)
        self.ax, self.body, self.edges = ax, body, body.edges()  # a lattice laid out once
        self.is_3d = body.dim == 3
        if self.is_3d != hasattr(ax, "get_proj"):
            kind = "3-D" if self.is_3d else "2-D"
            raise ValueError(f"a {kind} body needs {kind} axes; use new_axes(body)")
        positions = body.positions if positions is None else positions
        self.colour, self.up = colour, up
        self.rim = rim_height(body, positions, up) if colour == "sag" else 0.0
        limit = strain_limit or max(1e-3, float(np.max(np.abs(self.values(positions)), initial=0)))
        width = 0.6 if body.n_springs > 300 else 1.2  # a dense body's shape shows through
        strain = colour == "strain"
        style = {
            "cmap": STRAIN_MAP if strain else "cool",
            "norm": Normalize(-limit, limit) if strain else Normalize(0.0, limit),
            "linewidths": width,
            "stroke_width": width if strain else None,
        }
        lines = SpringLines3D if self.is_3d else SpringLines
        self.springs = lines(self._segments(positions), self.values(positions), **style)
        ax.add_collection(self.springs, autolim=False)  # `fit` sets the limits
        if self.is_3d:
            azimuth, elevation = (45.0, 30.0) if view is None else view
            ax.view_init(elev=elevation, azim=azimuth - 90.0, vertical_axis=up)
            for axis in (ax.xaxis, ax.yaxis, ax.zaxis):  # few ticks: no overlapping labels
                axis.set_major_locator(MaxNLocator(4))
            ax.tick_params(labelsize="small", pad=0)
        else:
            ax.set_aspect("equal")
        dot = 2.0 if body.n_particles > 500 else 3.5
        (self.free,) = ax.plot(*positions[~body.fixed].T, "o", ms=dot, color="0.15")
        (self.pinned,) = ax.plot(*positions[body.fixed].T, "s", ms=5, color="k")
        self.spheres = [(int(p), float(r)) for p, r in spheres]
        self.balls = [self._ball(positions[p], r) for p, r in self.spheres]
        self.fit(positions[None])
        if colorbar and body.n_springs:
            ax.figure.colorbar(
                self.springs,
                ax=ax,
                shrink=0.5,
                aspect=25,
                fraction=0.03,
                # 3-D: below the box, clear of the z axis's label and ticks at its right
                location="bottom" if self.is_3d else "right",
                pad=0.06 if self.is_3d else 0.02,
                label="strain" if strain else "sag below the rim",
            )
            if strain:
                add_key(ax.figure, max(width, 1.0))  # samples wide enough to read

    def values(self, positions: np.ndarray) -> np.ndarray:
        """What the springs' colour shows at ``positions``: strain or sag."""
        if self.colour == "sag":
            return sags(self.edges, positions, self.up, self.rim)
        return strains(self.edges, positions)

    def update(self, positions: np.ndarray) -> list:
        """Redraw for ``positions`` (N, d); return the changed artists (not the dots of
        an empty set of particles: none fixed, or all)."""
        self.springs.set_springs(self._segments(positions), self.values(positions))
        changed = [self.springs]
        for artist, mask in ((self.free, ~self.body.fixed), (self.pinned, self.body.fixed)):
            if self.is_3d:
                artist.set_data_3d(*positions[mask].T)
            else:
                artist.set_data(*positions[mask].T)
            if mask.any():
                changed.append(artist)
        for ball in self.balls:
            ball.remove()
        self.balls = [self._ball(positions[p], r) for p, r in self.spheres]
        return [*changed, *self.balls]

    def fit(self, frames: np.ndarray, margin: float = 0.05, thinnest: float = 0.2) -> None:
        """Set the limits to hold every position of ``frames`` (F, N, d) at equal scales.

        An axis spans at least ``thinnest`` of the widest, so a flat body stays readable.
        """
        points = frames.reshape(-1, frames.shape[-1])
        radii = np.zeros(len(points))
        for p, r in self.spheres:  # balls are part of the picture
            radii[p :: frames.shape[1]] = r
        low = (points - radii[:, None]).min(axis=0)
        high = (points + radii[:, None]).max(axis=0)
        width = max(float(np.max(high - low)), 1e-9)
        half = 0.5 * np.maximum(high - low, thinnest * width) + margin * width
        low, high = 0.5 * (low + high) - half, 0.5 * (low + high) + half
        self.ax.set(xlim=(low[0], high[0]), ylim=(low[1], high[1]), xlabel="x", ylabel="y")
        if self.is_3d:
            self.ax.set(zlim=(low[2], high[2]), zlabel="z")
            self.ax.set_box_aspect(tuple(high - low), zoom=1.25)  # less white around the box
            self._thin_out_foreshortened_axes()

    def _thin_out_foreshortened_axes(self) -> None:
        """Fewer ticks on an axis the view shortens, none on one seen end-on: no overlaps."""
        limits = np.array([self.ax.get_xlim(), self.ax.get_ylim(), self.ax.get_zlim()])
        centre = limits.mean(axis=1)
        ends = np.repeat(centre[None], 6, axis=0)
        for axis in range(3):
            ends[2 * axis : 2 * axis + 2, axis] = limits[axis]
        x, y, _ = proj3d.proj_transform(*ends.T, self.ax.get_proj())
        screen = np.hypot(np.diff(x)[::2], np.diff(y)[::2])
        for length, axis in zip(
            screen / screen.max(), (self.ax.xaxis, self.ax.yaxis, self.ax.zaxis)
        ):
            if length < 0.1:  # seen end-on
                axis.set_major_locator(NullLocator())
                axis.label.set_visible(False)
            elif length < 0.35:
                axis.set_major_locator(MaxNLocator(2))

    def _segments(self, positions: np.ndarray) -> np.ndarray:
        return np.stack([positions[self.edges.a], positions[self.edges.b]], axis=1)

    def _ball(self, centre: np.ndarray, radius: float) -> Artist:
        if not self.is_3d:
            return self.ax.add_patch(Circle(centre, radius, color=BALL_COLOUR, alpha=0.6))
        x, y, z = centre[:, None, None] + radius * _UNIT_SPHERE
        return self.ax.plot_surface(x, y, z, color=BALL_COLOUR, alpha=0.8, linewidth=0)


def plot_body(
    body: Body | Simulation,
    positions: np.ndarray | None = None,
    ax: Axes | None = None,
    *,
    view: Sequence[float] | None = None,
    up: str | None = None,
    spheres: Sequence[tuple[int, float]] = (),
    strain_limit: float | None = None,
    title: str | None = None,
    save: str | Path | None = None,
    colour: str = "strain",
) -> Figure:
    """Plot ``body`` (at ``positions``, default its own) with springs drawn by strain
    (or ``colour="sag"``, see `BodyView`); return the figure, also written to ``save``
    (.png, .pdf, .svg) if given. Given a simulation, "up" is against its gravity (`upright`)."""
    if isinstance(body, Simulation):
        up, body = resolve_up(up, body, body.body.dim), body.body
    ax = ax or new_axes(body)
    BodyView(
        ax,
        body,
        positions,
        strain_limit=strain_limit,
        view=view,
        up=up,
        spheres=spheres,
        colour=colour,
    )
    if title:
        ax.set_title(title)
    return save_figure(ax.figure, save)


def save_figure(figure: Figure, path: str | Path | None, dpi: float = 100.0) -> Figure:
    """Write ``figure`` to ``path`` (format from its suffix) unless ``path`` is None; return it."""
    if path is not None:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(path, dpi=dpi)
    return figure
