"""The ground's clamp in one loop over the particles, with its booking on the way.

`interaction.Ground.apply` on numpy arrays takes some thirty numpy calls on the
few particles below the plane, which for a small body cost more than its
springs; this loop does the same per particle: put it back on the plane, keep
its tangential velocity (times 1 - friction), give it the normal velocity of the
displacement it really made, and sum the contact's work (`equations.contact_work`)
and the friction's loss (`energy.kinetic_energy_removed`).
"""

import numba


@numba.njit(cache=True)
def ground_clamp(x, v, x_old, v_old, masses, fixed, normal, height, dt, friction):
    """Clamp the free particles with x·n < ``height`` onto the plane, in place; return the
    energy (J) the ground removed: friction's loss minus the contact's work.

    For such a particle (n = ``normal``, unit): x += (height - x·n) n;
    ṡ = (x - x_old)·n / dt; v ← (1 - friction)(v - (v·n) n) + ṡ n. The contact's
    work is ½ m (ṡ - v·n)(v_old·n + ṡ), friction's loss (1 - (1 - friction)²) ½ m |v_t|².
    """
    keep = 1.0 - friction
    work = 0.0
    rubbed = 0.0
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
        normal_speed = moved / dt
        tangential = 0.0
        for q in range(dim):
            along = v[i, q] - landing * normal[q]
            tangential += along * along
            v[i, q] = keep * along + normal_speed * normal[q]
        work += masses[i] * (normal_speed - landing) * (before + normal_speed)
        rubbed += masses[i] * tangential
    return 0.5 * (1.0 - keep * keep) * rubbed - 0.5 * work
