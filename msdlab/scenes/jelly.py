"""Jelly cube: the course brief's grid, rotated, dropped on the floor (seed ``002``, tasks 1-5).

The brief's template: an N×N×N grid (N = 20) at ``coord/N·2 - 1 + (0, 2.5, 0)``
(x, z in [-1, 1), y in [1.5, 3.5), spacing h = 2/N), unit masses, starting at
rest, a = (0, -0.001, 0), floor y = 0 that clamps y. Tasks 2-5 add springs of
rest length h (eq. 1.2), rotate the cube (task 3), add the √2·h and √3·h
neighbours (task 4: 26 neighbours, "jelly") and Verlet with damping λ
(eq. 1.3-1.4, task 5). Defaults: the solved setting k = 0.5, λ = 0.01,
dt = 0.4, rotation 58.3° about z. Units are the template's (length units,
time steps of the template's clock).
"""

from __future__ import annotations

from collections.abc import Sequence

from .. import Body, Gravity, Integrator, Simulation, Verlet, rotation_matrix
from ..interaction import Ground


def jelly_cube(
    *,
    size: int = 20,
    stiffness: float = 0.5,
    damping: float = 0.01,
    gravity: float = -0.001,
    angle: float = 58.3,
    axis: Sequence[float] = (0.0, 0.0, 1.0),
    neighbours: Sequence[int] = (1, 2, 3),
    friction: float = 0.0,
    dt: float = 0.4,
    integrator: Integrator | None = None,
) -> Simulation:
    """A ``size``³ jelly cube rotated by ``angle`` degrees about ``axis``, above the floor y = 0.

    ``neighbours`` (squared distances in grid units): (1,) gives the 6 axis
    springs, which have no shear stiffness, so a rotated cube collapses
    (task 3); (1, 2, 3) gives all 26 neighbours and the cube holds its shape
    (task 4). ``damping`` is the Verlet λ of eq. (1.4), in [0, 1).
    """
    spacing = 2.0 / size
    body = Body.grid(
        (size, size, size),
        spacing=spacing,
        stiffness=stiffness,
        neighbours=neighbours,
        origin=(-1.0, 1.5, -1.0),
    )
    body.rotate(rotation_matrix(angle, axis))
    forces = [Gravity((0.0, gravity, 0.0)), Ground(0.0, friction=friction)]
    return Simulation(body, integrator or Verlet(damping), dt, forces)
