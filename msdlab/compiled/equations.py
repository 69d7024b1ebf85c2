"""The equations of `msdlab.equations`, compiled by numba for numbers and inlined in the loops.

The same functions, not copies: each is `msdlab.equations`'s own code, handed to
``numba.njit``, so the compiled loops compute exactly what the numpy kernel does.
"""

import types
from collections.abc import Callable

import numba

from .. import equations


def _compiled(function: Callable, **helpers: Callable) -> Callable:
    """``function``'s own code compiled by numba, its calls to other equations (``helpers``)
    going to their compiled forms: numba cannot call a plain Python function."""
    scope = {**function.__globals__, **helpers}
    twin = types.FunctionType(function.__code__, scope, function.__name__, function.__defaults__)
    return numba.njit(cache=True, inline="always")(twin)


spring_tension = _compiled(equations.spring_tension)
spring_energy = _compiled(equations.spring_energy)
dashpot_power = _compiled(equations.dashpot_power)
transverse_stiffness = _compiled(equations.transverse_stiffness)
acceleration = _compiled(equations.acceleration)
ground_contact = _compiled(equations.ground_contact)
