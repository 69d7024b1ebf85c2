"""The scenes by name, for the command line: what each builds, how long it runs, how to view it."""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass

from .. import Simulation
from . import cloth, gallery, jelly, trampoline


@dataclass(frozen=True)
class Scene:
    """A named scene: ``build(**settings)`` returns a ready `Simulation`."""

    name: str
    build: Callable[..., Simulation]
    description: str
    duration: float  # how long `msdlab run` runs it by default (s, or frames for 2-D scenes)
    frames: int = 100  # frames an animation shows
    view: tuple[float, float] = (45.0, 30.0)  # azimuth, elevation (degrees) of 3-D views
    up: str = "z"  # the vertical axis
    unit: str = "s"  # of time
    energy_unit: str = "J"
    colour: str = "strain"  # what the springs' colour shows in animations: strain or sag

    def settings(self) -> dict[str, object]:
        """The keyword arguments of ``build`` and their defaults."""
        return {
            name: p.default
            for name, p in inspect.signature(self.build).parameters.items()
            if p.kind is p.KEYWORD_ONLY
        }


def _gallery(name: str, build: Callable[..., Simulation], description: str) -> Scene:
    return Scene(name, build, description, duration=600.0, frames=120, unit="frames")


SCENES: dict[str, Scene] = {
    scene.name: scene
    for scene in (
        Scene(
            "jelly-cube",
            jelly.jelly_cube,
            "the brief's 20³ grid, rotated 58.3°, 26 neighbours, damped Verlet, lands on the floor",
            duration=600.0,
            frames=60,
            view=(-30.0, 20.0),
            up="y",
            # the template's own units: dt = 0.4 and g = -0.001 are not seconds and m/s²
            unit="template units",
            energy_unit="template units",
        ),
        Scene(
            "trampoline",
            trampoline.trampoline,
            "a 1 kg ball dropped on a pre-tensioned 7×7 net with a fixed rim (--experiments)",
            duration=5.0,
            frames=60,
            view=(15.0, 12.0),  # from the side, just above the rim: the sag shows
            colour="sag",  # and its depth is coloured
        ),
        Scene(
            "cloth",
            cloth.cloth,
            "a 10×10 cloth over 10 m × 8 m at z = 10 m, pinned at two corners, damped by λ",
            duration=10.0,
            frames=100,
            view=(-30.0, 20.0),
        ),
        _gallery(
            "two-particles", gallery.two_particles, "two particles and one spring, pulled apart"
        ),
        _gallery("triangle", gallery.triangle, "a triangle of springs falling inside hard walls"),
        _gallery(
            "hanging-particle", gallery.hanging_particle, "a particle hanging from a fixed one"
        ),
        _gallery(
            "rope", gallery.rope, "18 particles, the first fixed, swinging down under gravity"
        ),
        _gallery("hanging-rope", gallery.hanging_rope, "a rope fixed at both ends: a catenary"),
        _gallery("wheel", gallery.wheel, "a ring of particles with spokes to a hub, bouncing"),
        _gallery("blob", gallery.blob, "60 points on a circle joined by chords: a bouncy bag"),
        _gallery("mesh", gallery.mesh, "a 10×10 square mesh with both diagonals (342 springs)"),
        _gallery(
            "driven-mesh",
            gallery.driven_mesh,
            "the mesh hanging from a particle moved by sine + noise",
        ),
        _gallery("truss", gallery.truss, "a narrow braced truss (a worm) on the floor"),
    )
}


def get_scene(name: str) -> Scene:
    """The scene called ``name``; the error lists the valid names."""
    try:
        return SCENES[name]
    except KeyError:
        raise ValueError(f"unknown scene {name!r}; choose one of: {', '.join(SCENES)}") from None
