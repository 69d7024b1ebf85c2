"""Due dates and late work: when a submission was due, and what handing it in late costs.

A late policy is written as comma-separated ``key=value`` parts (every part optional)::

    grace=15m,penalty=10%/day,cap=50%,cutoff=7d

- ``grace``: lateness up to this long costs nothing (an upload that took a minute).
- ``penalty``: what each started period of lateness costs, counted from the due date
  (not from the end of the grace period): ``10%/day`` takes 10 % of the points earned per
  started day, ``2/hour`` takes 2 points per started hour.
- ``cap``: the most the penalty takes: ``50%`` of the points earned, or ``6`` points.
- ``cutoff``: work handed in later than this after the due date is not accepted (0 points).

Durations are a number and a unit: ``s``, ``m`` (minutes), ``h``, ``d`` or ``w``. The
penalty never takes more than the points earned:

    penalty = min(periods × per_period, cap, points),  periods = ⌈lateness / period⌉.

A due date is an ISO 8601 date and time (``2027-03-01T23:59``). One without an offset is
the wall-clock time in the course's time zone (``--timezone Europe/Berlin``; by default
the grading machine's), daylight saving time included; one with an offset
(``2027-03-01T23:59+01:00``, ``...Z``) is that instant everywhere.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from datetime import datetime, timedelta, tzinfo
from fractions import Fraction
from pathlib import Path
from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

UNITS = {"s": 1, "m": 60, "h": 3600, "d": 86400, "w": 604800}
PERIODS = {"hour": timedelta(hours=1), "day": timedelta(days=1), "week": timedelta(weeks=1)}
_DURATION = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*([smhdw])\s*$")
_AMOUNT = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*(%?)\s*$")
EXAMPLE = "grace=15m,penalty=10%/day,cap=50%,cutoff=7d"


@dataclass(frozen=True)
class Amount:
    """Points, or a percentage of the points earned."""

    value: Fraction
    percent: bool

    def of(self, points: Fraction) -> Fraction:
        """The points this amount is of ``points`` earned."""
        return points * self.value / 100 if self.percent else self.value

    def __str__(self) -> str:
        return f"{format_points(self.value)}{'%' if self.percent else ' points'}"


@dataclass(frozen=True)
class Lateness:
    """What handing in ``late`` after the due date cost, and why, in the student's words."""

    late: timedelta
    penalty: Fraction
    accepted: bool
    reason: str


@dataclass(frozen=True)
class LatePolicy:
    """Grace period, penalty per started period, cap and cutoff (see the module docstring)."""

    grace: timedelta = timedelta(0)
    per_period: Amount = Amount(Fraction(0), False)
    period: timedelta = PERIODS["day"]
    cap: Amount | None = None
    cutoff: timedelta | None = None

    @classmethod
    def parse(cls, text: str) -> LatePolicy:
        """The policy written as ``grace=15m,penalty=10%/day,cap=50%,cutoff=7d``."""
        settings: dict[str, object] = {}
        for part in (p.strip() for p in text.split(",") if p.strip()):
            key, _, value = part.partition("=")
            key = key.strip().lower()
            if key in ("grace", "cutoff"):
                settings[key] = parse_duration(value, f"--late-policy {key}")
            elif key == "penalty":
                amount, _, period = value.partition("/")
                if period.strip().lower() not in PERIODS:
                    raise ValueError(
                        f"--late-policy penalty={value}: say per what, e.g. penalty=10%/day "
                        f"or penalty=2/hour ({', '.join(PERIODS)})"
                    )
                settings["per_period"] = parse_amount(amount, "--late-policy penalty")
                settings["period"] = PERIODS[period.strip().lower()]
            elif key == "cap":
                settings["cap"] = parse_amount(value, "--late-policy cap")
            else:
                raise ValueError(
                    f"--late-policy: unknown part {part!r}; write it like {EXAMPLE} "
                    "(grace, penalty, cap, cutoff; each optional)"
                )
        return cls(**settings)

    def charge(self, points: Fraction, late: timedelta) -> Lateness:
        """What handing in ``late`` after the due date takes from ``points`` earned (none
        from points below zero, which manual changes can make)."""
        points = max(points, Fraction(0))
        if late <= timedelta(0):
            return Lateness(late, Fraction(0), True, "handed in on time")
        said = f"handed in {format_duration(late)} late"
        if self.cutoff is not None and late > self.cutoff:
            return Lateness(
                late, points, False,
                f"{said}, after the cutoff of {format_duration(self.cutoff)}: not accepted",
            )  # fmt: skip
        if late <= self.grace:
            return Lateness(late, Fraction(0), True, f"{said}, within the grace period")
        periods = -(-late // self.period)  # started periods, in whole microseconds
        unit = next(name for name, length in PERIODS.items() if length == self.period)
        taken = periods * self.per_period.of(points)
        of = f" of {format_points(points)} points" if self.per_period.percent else ""
        reason = f"{said}: {periods} started {unit}{'s' * (periods != 1)} × {self.per_period}{of}"
        if self.cap is not None and taken > self.cap.of(points):
            taken = self.cap.of(points)
            reason += f", capped at {self.cap}"
        taken = min(taken, points)
        return Lateness(late, taken, True, f"{reason} = {format_points(taken)} points")


def parse_duration(text: str, what: str) -> timedelta:
    """``15m``, ``36h``, ``2d`` as a duration; a clear error naming ``what`` otherwise."""
    match = _DURATION.match(text)
    if match is None:
        raise ValueError(f"{what}={text!r}: write a duration like 15m, 36h or 2d")
    return timedelta(seconds=float(match.group(1)) * UNITS[match.group(2)])


def parse_amount(text: str, what: str) -> Amount:
    """``10%`` (of the points earned) or ``2`` (points)."""
    match = _AMOUNT.match(text)
    if match is None:
        raise ValueError(f"{what}={text!r}: write points like 2 or a percentage like 10%")
    return Amount(Fraction(match.group(1)), bool(match.group(2)))


def time_zone(name: str | None) -> tzinfo | None:
    """The zone called ``name`` (IANA, e.g. Europe/Berlin); None: the machine's own."""
    if not name:
        return None
    try:
        return ZoneInfo(name)
    except (ZoneInfoNotFoundError, ValueError):
        raise ValueError(
            f"--timezone {name!r} is not a time zone; give an IANA name like Europe/Berlin or UTC"
        ) from None


def parse_due(text: str, zone: tzinfo | None, what: str = "--due") -> datetime:
    """The instant ``text`` names: with an offset as written, without one in ``zone``
    (None: the grading machine's zone, as it was on that date)."""
    try:
        due = datetime.fromisoformat(re.sub(r"[zZ]$", "+00:00", text.strip()))
    except ValueError:
        raise ValueError(
            f"{what} {text!r} is not a date and time; write it like 2027-03-01T23:59 "
            "(add +01:00 or Z to give the offset)"
        ) from None
    if "T" not in text.strip().upper() and " " not in text.strip():
        raise ValueError(f"{what} {text!r} has no time of day; write it like {text.strip()}T23:59")
    if due.tzinfo is not None:
        return due
    return due.replace(tzinfo=zone) if zone is not None else due.astimezone()


def read_extensions(path: Path, due: datetime, zone: tzinfo | None) -> dict[str, datetime]:
    """Each student's own due date from a CSV with a header ``id,extension`` (a duration
    added to the class's due date, e.g. ``2d``) or ``id,due`` (a date and time); other
    columns (a reason, say) are kept out of the way."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no extensions file at {path}")
    own: dict[str, datetime] = {}
    with path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.DictReader(handle)
        columns = [c.strip().lower() for c in reader.fieldnames or []]
        if "id" not in columns or not {"extension", "due"} & set(columns):
            raise ValueError(
                f"{path}: the first line must name the columns, e.g. 'id,extension,reason' "
                "(extension like 2d) or 'id,due' (due like 2027-03-03T23:59)"
            )
        for number, row in enumerate(reader, start=2):
            cells = {k.strip().lower(): (v or "").strip() for k, v in row.items() if k}
            if not cells.get("id"):
                continue
            where = f"{path}, line {number}"
            if cells.get("due"):
                own[cells["id"]] = parse_due(cells["due"], zone, f"{where}: due")
            elif cells.get("extension"):
                own[cells["id"]] = due + parse_duration(cells["extension"], f"{where}: extension")
            else:
                raise ValueError(f"{where}: give an extension (like 2d) or a due date")
    return own


def format_points(points: Fraction) -> str:
    """Points as a short decimal: 7, 7.5, 6.67 (two decimals at most, halves rounded up)."""
    hundredths = math.floor(points * 100 + Fraction(1, 2))
    text = f"{hundredths / 100:.2f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def format_duration(late: timedelta) -> str:
    """``1 d 2 h 5 min`` (whole minutes, rounded up)."""
    minutes = math.ceil(late.total_seconds() / 60)
    days, rest = divmod(minutes, 1440)
    hours, minutes = divmod(rest, 60)
    parts = [f"{days} d" * bool(days), f"{hours} h" * bool(hours), f"{minutes} min" * bool(minutes)]
    return " ".join(p for p in parts if p) or "0 min"
