"""Spring: a Hookean spring, with an optional dashpot, between two particles."""

from __future__ import annotations

import math
import operator

import numpy as np

from .. import equations
from .bound import Bound, Field
from .errors import check_non_negative, check_positive, shown


def _stiffness(value: float) -> float:
    return float(check_non_negative("stiffness", value, "Use k >= 0 (N/m)."))


def _rest_length(value: float) -> float:
    return check_positive("rest_length", value, "A spring needs a rest length > 0 (m).")


def _damping(value: float) -> float:
    return float(check_non_negative("damping", value, "Use a dashpot coefficient c >= 0 (N·s/m)."))


class Spring(Bound):
    """A spring of stiffness k (N/m) and rest length l (m) joining particles ``a`` and ``b``.

    The force on ``a`` is eq. (1.2) of the brief plus a dashpot of coefficient c
    (N·s/m) acting along the spring only (so it never damps rigid rotation)::

        n   = (x_a - x_b) / |x_a - x_b|
        f_a = k (l - |x_a - x_b|) n  -  c ((v_a - v_b) · n) n,     f_b = -f_a

    ``rest_length=None`` takes the distance between the particles when the spring
    is added to a body. `Spring.force` and the numpy kernel (`msdlab.engine.backends.numpy`) apply
    `equations.spring_force`; the compiled loops (`msdlab.engine.backends.numba`) its terms,
    `equations.spring_state`, one spring at a time. In a body, the object reads and writes
    spring ``index`` of the body's spring set (`Body.set_springs`).
    """

    a = Field("a", "Index of the first particle.", kind=int)
    b = Field("b", "Index of the second particle.", kind=int)
    stiffness = Field("stiffness", "Stiffness k (N/m).", _stiffness)
    rest_length = Field("rest_lengths", "Rest length l (m); None until in a body.", _rest_length)
    damping = Field("damping", "Dashpot coefficient c (N·s/m).", _damping)

    def __init__(
        self,
        a: int,
        b: int,
        stiffness: float = 1.0,
        rest_length: float | None = None,
        damping: float = 0.0,
    ) -> None:
        super().__init__()
        try:
            self._own.update(a=operator.index(a), b=operator.index(b))
        except TypeError:
            raise TypeError(
                f"a spring joins two particle indices (int), got {shown(a)} and {shown(b)}; "
                "use the value returned by body.add_particle(...)"
            ) from None
        if a == b:
            raise ValueError(f"a spring cannot join particle {a} to itself; pick two particles")
        self.stiffness, self.damping = stiffness, damping
        self._own["rest_length"] = None if rest_length is None else _rest_length(rest_length)

    def read(self, array: str) -> float:
        """This spring's value ``array`` in its body's spring set (`springs.SpringValues`)."""
        return getattr(self.body.spring_set.spring(self.index), array)

    def write(self, array: str, value: float) -> None:
        """Set this spring's value ``array`` in its body (`Body.set_springs`)."""
        self.body.set_springs([self.index], **{array: value})

    def _ends(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        if self.body is None:
            raise RuntimeError("add the spring to a body first: body.add_spring(spring)")
        x, v = self.body.positions, self.body.velocities
        return x[self.a], x[self.b], v[self.a], v[self.b]

    def length(self) -> float:
        """Current length |x_a - x_b| (m)."""
        x_a, x_b, _, _ = self._ends()
        return math.dist(x_a, x_b)

    def force(self) -> np.ndarray:
        """Force on particle ``a`` (N), eq. (1.2) plus the dashpot; ``b`` feels minus this."""
        x_a, x_b, v_a, v_b = self._ends()
        d, w = np.zeros(3), np.zeros(3)  # three coordinates, the third 0 in 2-D
        d[: len(x_a)], w[: len(x_a)] = x_a - x_b, v_a - v_b
        f = equations.spring_force(self.stiffness, self.rest_length, self.damping, d, w)[0]
        return np.array(f[: len(x_a)])

    def energy(self) -> float:
        """Elastic energy ½ k (|x_a - x_b| - l)² (J)."""
        return equations.spring_energy(self.stiffness, self.rest_length, self.length())

    def __repr__(self) -> str:
        where = f"index={self.index}, " if self.body is not None else ""
        return (
            f"Spring({where}a={self.a}, b={self.b}, stiffness={self.stiffness:g}, "
            f"rest_length={self.rest_length}, damping={self.damping:g})"
        )
