"""The equations of `msdlab.engine.equations`, compiled by numba for numbers and inlined in
the loops.

The same functions, not copies: each is `msdlab.engine.equations`'s own code, handed to
``numba.njit``, so the compiled loops compute exactly what the numpy kernel does.
"""

import numba

from ... import equations

_inlined = numba.njit(cache=True, inline="always")

spring_state = _inlined(equations.spring_state)
spring_energy = _inlined(equations.spring_energy)
dashpot_power = _inlined(equations.dashpot_power)
transverse_stiffness = _inlined(equations.transverse_stiffness)
spring_jacobian = _inlined(equations.spring_jacobian)
acceleration = _inlined(equations.acceleration)
ground_contact = _inlined(equations.ground_contact)
damping_kick_work = _inlined(equations.damping_kick_work)


@numba.njit(cache=True, inline="always")
def separation(x, i, j):
    """d = x_i - x_j (m) of positions ``x`` (N, d), three coordinates (the third 0 in 2-D)."""
    d2 = x[i, 2] - x[j, 2] if x.shape[1] == 3 else 0.0
    return x[i, 0] - x[j, 0], x[i, 1] - x[j, 1], d2
