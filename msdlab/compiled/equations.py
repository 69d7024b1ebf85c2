"""The equations of `msdlab.equations`, compiled by numba for numbers and inlined in the loops.

The same functions, not copies: each is `msdlab.equations`'s own, handed to
``numba.njit``, so the compiled loops compute exactly what the numpy kernel does.
"""

import numba

from .. import equations

spring_force = numba.njit(cache=True, inline="always")(equations.spring_force)
spring_tension = numba.njit(cache=True, inline="always")(equations.spring_tension)
spring_energy = numba.njit(cache=True, inline="always")(equations.spring_energy)
dashpot_power = numba.njit(cache=True, inline="always")(equations.dashpot_power)
transverse_stiffness = numba.njit(cache=True, inline="always")(equations.transverse_stiffness)
acceleration = numba.njit(cache=True, inline="always")(equations.acceleration)
