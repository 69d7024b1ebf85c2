"""The units a simulation's numbers are in: SI by default; the p5.js gallery's pixels
and frames. Views label times, lengths and energies with them."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Units:
    """Names of the units of time, length and mass ("" for masses that are pure numbers)."""

    time: str = "s"
    length: str = "m"
    mass: str = "kg"

    @property
    def energy(self) -> str:
        """The unit of energy, mass · length² / time²: J in SI."""
        if self == SI:
            return "J"
        mass = f"{self.mass}·" if self.mass else ""
        return f"{mass}{self.length}²/{self.time}²"


SI = Units()
PAGE = Units(time="frame", length="px", mass="")  # the p5.js page: unit masses
