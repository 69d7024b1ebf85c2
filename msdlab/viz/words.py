"""The live view in words, for a screen reader: what the body does, the particle in hand
and how the energy is divided (a short line the page announces when it changes), and on
request the whole state (the body, its size, its lowest point, its energy table).

`summarise` reads a simulation into a `BodySummary`; `brief` and `full` turn a summary
into sentences, so the words are tested without a browser.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..engine.simulation.simulation import Simulation

STILL = 0.01  # of the body's size a second watched: slower than this, it is resting
TOUCHING = 0.02  # of the body's height: a lowest point this near the floor touches it
SHARE_STEP = 10  # per cent: the shares said are rounded to this (a new line only on change)
NOTHING = 1e-9  # of the largest energy: a mechanism's share this small is not said
PUT_IN = ("hand", "driven")  # ledger entries of work put in, not energy lost
AXES = "xyz"


@dataclass(frozen=True)
class BodySummary:
    """What the words need of a body now, in the simulation's units.

    ``size``: its extent along each axis; ``lowest``: its lowest point's height above the
    floor (or above the level gravitational energy is counted from, without a floor);
    ``rise``: the centre of mass's velocity along the vertical; ``fastest``: the fastest
    particle's speed; ``still``: a speed under which the body counts as at rest; ``held``
    and ``held_at``: the particle in hand and its position; ``energy``: the view's ledger
    (`widget.energies`); ``stopped``: why the simulation stopped ("" while it runs).
    """

    particles: int
    springs: int
    pinned: int
    size: tuple[float, ...]
    lowest: float
    has_floor: bool
    up: int
    rise: float
    fastest: float
    still: float
    held: int | None
    held_at: tuple[float, ...] | None
    energy: dict
    length_unit: str
    energy_unit: str
    time_unit: str
    stopped: str = ""


def summarise(
    sim: Simulation,
    velocities: np.ndarray,
    energy: dict,
    *,
    springs: int,
    up: int,
    level: float,
    has_floor: bool,
    held: int | None,
    watched: float,
    energy_unit: str,
    stopped: str = "",
) -> BodySummary:
    """The summary of ``sim`` now, with its ``velocities`` at the positions' time and its
    ``energy``; ``springs``: how many it has (counted once: a lattice lays its springs
    out to count them); ``level``: the floor's height along axis ``up``; ``watched``:
    simulated time per second of watching (the view's pace)."""
    x, masses = sim.body.positions, sim.body.masses
    size = tuple(float(s) for s in np.ptp(x, axis=0))
    mass = float(np.sum(masses))
    rise = float(masses @ velocities[:, up]) / mass if mass > 0 else 0.0
    return BodySummary(
        particles=len(sim.body),
        springs=springs,
        pinned=int(np.count_nonzero(sim.body.fixed)) - (held is not None),
        size=size,
        lowest=float(x[:, up].min()) - level,
        has_floor=has_floor,
        up=up,
        rise=rise,
        fastest=float(np.sqrt(np.max(np.sum(velocities**2, axis=1)))) if len(x) else 0.0,
        still=STILL * max(max(size), 1e-12) / watched,
        held=held,
        held_at=None if held is None else tuple(float(c) for c in x[held]),
        energy=energy,
        length_unit=sim.units.length,
        energy_unit=energy_unit,
        time_unit=sim.units.time,
        stopped=stopped,
    )


def motion(summary: BodySummary) -> str:
    """What the body is doing, in a few words: stopped, resting, bouncing on the floor,
    falling, rising, swinging (pinned or held) or moving (no floor, nothing holds it)."""
    s = summary
    if s.stopped:
        return "stopped: the simulation blew up"
    on_floor = s.has_floor and s.lowest <= TOUCHING * max(s.size[s.up], max(s.size), 1e-12)
    if s.fastest < s.still:
        return "resting on the floor" if on_floor else "at rest"
    if on_floor:
        return "bouncing on the floor"
    if s.pinned or s.held is not None:
        return "swinging"
    if s.rise < -s.still:
        return "falling"
    if s.rise > s.still:
        return "rising"
    return "moving"


def energy_parts(energy: dict) -> dict[str, float]:
    """The energy in four parts: kinetic, spring, gravity (and other potential, contact),
    and lost (what drag, dampers, the floor and the integrator took out)."""
    lost = sum(v for name, v in energy["dissipated"].items() if name not in PUT_IN)
    return {
        "kinetic": energy["kinetic"],
        "spring": energy["elastic"],
        "gravity": energy["gravitational"] + energy.get("other", 0.0),
        "lost": lost,
    }


def shares(energy: dict) -> dict[str, int]:
    """Each part's share of the energy: per cent of the parts' sizes in steps of
    `SHARE_STEP`, summing to 100 (the largest remainders rounded up)."""
    parts = {name: abs(value) for name, value in energy_parts(energy).items()}
    whole = sum(parts.values())
    if whole <= 0:
        return dict.fromkeys(parts, 0)
    steps = {name: 100 * v / whole / SHARE_STEP for name, v in parts.items()}
    kept = {name: math.floor(v) for name, v in steps.items()}
    left = 100 // SHARE_STEP - sum(kept.values())
    for name in sorted(steps, key=lambda n: kept[n] - steps[n])[:left]:
        kept[name] += 1
    return {name: SHARE_STEP * k for name, k in kept.items()}


def number(value: float, scale: float) -> str:
    """``value`` to a hundredth of ``scale`` (a body's size): -0.4031 of 1.2 is "-0.40"."""
    places = max(0, -math.floor(math.log10(scale / 100))) if scale > 0 else 2
    text = f"{value:.{places}f}"
    return "0" if float(text) == 0 else text


def place(at: tuple[float, ...], scale: float, unit: str) -> str:
    """A position in words: "x 0.12, y -0.40 m"."""
    return ", ".join(f"{AXES[k]} {number(c, scale)}" for k, c in enumerate(at)) + f" {unit}"


def energy_line(energy: dict) -> str:
    """How the energy is divided: "energy 60 % kinetic, 30 % spring, 10 % gravity"."""
    split = shares(energy)
    said = [f"{share} % {name}" for name, share in split.items() if share > 0]
    return "energy " + (", ".join(said) if said else "zero")


def brief(summary: BodySummary) -> str:
    """The short line the page announces: what the body does, the particle in hand and
    where, how the energy is divided."""
    s = summary
    line = f"The body is {motion(s)}."
    if s.held is not None and s.held_at is not None:
        line += f" Particle {s.held} in hand at {place(s.held_at, max(s.size), s.length_unit)}."
    return f"{line} {energy_line(s.energy).capitalize()}."


def energy_table(summary: BodySummary) -> list[tuple[str, float]]:
    """The energy table: in the body (kinetic, spring, gravity), what each mechanism took
    out, the work put in by the hand or driven particles, and the total (in the body +
    taken out - put in)."""
    e = summary.energy
    rows = [("kinetic", e["kinetic"]), ("spring", e["elastic"]), ("gravity", e["gravitational"])]
    if e.get("other"):
        rows.append(("other potential", e["other"]))
    largest = max(abs(v) for _, v in rows) + max(map(abs, e["dissipated"].values()), default=0)
    for name, value in e["dissipated"].items():
        if abs(value) <= NOTHING * largest:  # nothing booked yet, or rounding's crumbs
            continue
        if name in PUT_IN:
            rows.append((f"{'your hand' if name == 'hand' else 'driven particles'} put in", -value))
        else:
            rows.append((f"taken out by {name}", value))
    total = sum(v for name, v in rows if not name.endswith("put in"))
    total -= sum(v for name, v in rows if name.endswith("put in"))
    return [*rows, ("total", total)]


def counted(count: int, noun: str) -> str:
    """The noun counted: "1 spring", "2 springs"."""
    return f"{count} {noun}{'' if count == 1 else 's'}"


def full(summary: BodySummary) -> str:
    """The whole state in words: the body, its size, its lowest point, what it does, the
    particle in hand and the energy table."""
    s, unit = summary, summary.length_unit
    scale = max(s.size) or 1.0
    pinned = f", {s.pinned} of them pinned" if s.pinned else ""
    parts = f"{counted(s.particles, 'particle')} and {counted(s.springs, 'spring')}"
    words = [f"A {len(s.size)}-D body of {parts}{pinned}."]
    extent = ", ".join(f"{number(v, scale)} {unit} along {AXES[k]}" for k, v in enumerate(s.size))
    words.append(f"Its size: {extent}.")
    above = "the floor" if s.has_floor else "where gravity's energy is counted from"
    words.append(f"Its lowest point is {number(s.lowest, scale)} {unit} above {above}.")
    words.append(f"It is {motion(s)}.")
    if s.held is not None and s.held_at is not None:
        words.append(f"Particle {s.held} is in hand at {place(s.held_at, scale, unit)}.")
    table = "; ".join(f"{name} {value + 0.0:.3g}" for name, value in energy_table(s))
    words.append(f"Energy in {s.energy_unit}: {table}.")
    words.append(f"Simulated time t = {s.energy['time']:.4g} {s.time_unit}.")
    return " ".join(words)
