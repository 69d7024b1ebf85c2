"""Spring: a Hookean spring, with an optional dashpot, between two particles."""

from __future__ import annotations

import math
import operator

import numpy as np

from . import equations
from .bound import Bound
from .errors import check_non_negative, check_positive


class Spring(Bound):
    """A spring of stiffness k (N/m) and rest length l (m) joining particles ``a`` and ``b``.

    The force on ``a`` is eq. (1.2) of the brief plus a dashpot of coefficient c
    (N·s/m) acting along the spring only (so it never damps rigid rotation)::

        n   = (x_a - x_b) / |x_a - x_b|
        f_a = k (l - |x_a - x_b|) n  -  c ((v_a - v_b) · n) n,     f_b = -f_a

    ``rest_length=None`` takes the distance between the particles when the spring
    is added to a body. This class is the readable one-spring version; it and the
    spring kernels (`msdlab.kernels`) all apply `equations.spring_force`.
    """

    def __init__(
        self,
        a: int,
        b: int,
        stiffness: float = 1.0,
        rest_length: float | None = None,
        damping: float = 0.0,
    ) -> None:
        try:
            a, b = operator.index(a), operator.index(b)
        except TypeError:
            raise TypeError(
                f"a spring joins two particle indices (int), got {a!r} and {b!r}; "
                "use the value returned by body.add_particle(...)"
            ) from None
        if a == b:
            raise ValueError(f"a spring cannot join particle {a} to itself; pick two particles")
        check_non_negative("stiffness", stiffness, "Use k >= 0 (N/m); a negative k pushes apart.")
        check_non_negative("damping", damping, "Use a dashpot coefficient c >= 0 (N·s/m).")
        if rest_length is not None:
            rest_length = check_positive(
                "rest_length", rest_length, "A spring needs a rest length > 0 (m)."
            )
        super().__init__(
            a=a, b=b, stiffness=float(stiffness), rest_length=rest_length, damping=float(damping)
        )

    def _get(self, name: str, array: str) -> float:
        return self._own[name] if self._body is None else getattr(self._body, array)[self._index]

    @property
    def a(self) -> int:
        """Index of the first particle."""
        return int(self._get("a", "spring_a"))

    @property
    def b(self) -> int:
        """Index of the second particle."""
        return int(self._get("b", "spring_b"))

    @property
    def stiffness(self) -> float:
        """Stiffness k (N/m)."""
        return float(self._get("stiffness", "stiffness"))

    @stiffness.setter
    def stiffness(self, value: float) -> None:
        check_non_negative("stiffness", value)
        self._set("stiffness", "stiffness", value)

    @property
    def rest_length(self) -> float | None:
        """Rest length l (m); None until added to a body when it was not given."""
        value = self._get("rest_length", "rest_lengths")
        return None if value is None else float(value)

    @rest_length.setter
    def rest_length(self, value: float) -> None:
        self._set("rest_length", "rest_lengths", check_positive("rest_length", value))

    @property
    def damping(self) -> float:
        """Dashpot coefficient c (N·s/m)."""
        return float(self._get("damping", "spring_damping"))

    @damping.setter
    def damping(self, value: float) -> None:
        check_non_negative("damping", value)
        self._set("damping", "spring_damping", value)

    def _set(self, name: str, array: str, value: float) -> None:
        if self._body is None:
            self._own[name] = float(value)
        else:
            getattr(self._body, array)[self._index] = value

    def _ends(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        if self._body is None:
            raise RuntimeError("add the spring to a body first: body.add_spring(spring)")
        x, v = self._body.positions, self._body.velocities
        return x[self.a], x[self.b], v[self.a], v[self.b]

    def length(self) -> float:
        """Current length |x_a - x_b| (m)."""
        x_a, x_b, _, _ = self._ends()
        return math.dist(x_a, x_b)

    def force(self) -> np.ndarray:
        """Force on particle ``a`` (N), eq. (1.2) plus the dashpot; ``b`` feels minus this."""
        x_a, x_b, v_a, v_b = self._ends()
        length = math.dist(x_a, x_b)
        if length == 0.0:  # coincident ends: no direction, no force
            return np.zeros_like(x_a)
        closing = float(np.dot(v_a - v_b, x_a - x_b))
        along = equations.spring_force(
            self.stiffness, self.rest_length, length, self.damping, closing
        )
        return along * (x_a - x_b) / length

    def energy(self) -> float:
        """Elastic energy ½ k (|x_a - x_b| - l)² (J)."""
        return equations.spring_energy(self.stiffness, self.rest_length, self.length())

    def __repr__(self) -> str:
        where = f"index={self._index}, " if self._body is not None else ""
        return (
            f"Spring({where}a={self.a}, b={self.b}, stiffness={self.stiffness:g}, "
            f"rest_length={self.rest_length}, damping={self.damping:g})"
        )
