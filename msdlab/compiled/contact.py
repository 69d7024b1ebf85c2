"""The ground's clamp in one loop over the particles, with its booking on the way.

The numpy backend's `kernels.ground_clamp` takes some thirty numpy calls on the few
particles below the plane, which for a small body cost more than its springs; this loop
does the same per particle: put it back on the plane and apply
`equations.ground_contact` (its new normal speed and the energy removed).
"""

import numba

from .equations import ground_contact


@numba.njit(cache=True)
def ground_clamp(x, v, x_old, v_old, masses, fixed, normal, height, dt, friction):
    """Clamp the free particles with x·n < ``height`` onto the plane, in place; return the
    energy (J) the ground removed (`kernels.ground_clamp`, one particle at a time)."""
    keep = 1.0 - friction
    removed = 0.0
    dim = x.shape[1]
    for i in range(len(x)):
        above = 0.0
        for q in range(dim):
            above += x[i, q] * normal[q]
        if not above < height or fixed[i]:
            continue
        depth = height - above
        landing = moved = before = 0.0
        for q in range(dim):
            x[i, q] += depth * normal[q]
            landing += v[i, q] * normal[q]
            moved += (x[i, q] - x_old[i, q]) * normal[q]
            before += v_old[i, q] * normal[q]
        tangential = 0.0
        for q in range(dim):
            v[i, q] -= landing * normal[q]
            tangential += v[i, q] * v[i, q]
        normal_speed, lost = ground_contact(masses[i], landing, moved, before, tangential, dt, keep)
        removed += lost
        for q in range(dim):
            v[i, q] = keep * v[i, q] + normal_speed * normal[q]
    return removed
