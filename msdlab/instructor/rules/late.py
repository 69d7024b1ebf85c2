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

import math
import re
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone, tzinfo
from fractions import Fraction
from pathlib import Path
from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

from ..outputs.csv_files import read_table, too_many_fields
from .problems import Problem, raise_refused

MAX_DURATION = timedelta(days=366)
"""The longest grace period, cutoff or extension (a year: longer is a typo)."""
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
        """The policy written as ``grace=15m,penalty=10%/day,cap=50%,cutoff=7d``; an
        `InstructorFileError` naming every mistake in it."""
        settings, problems = _policy_settings(text)
        raise_refused(problems)
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


def _policy_settings(text: str) -> tuple[dict[str, object], list[Problem]]:
    """The `LatePolicy` settings written in ``text``, and its mistakes."""
    settings: dict[str, object] = {}
    problems: list[Problem] = []
    given: set[str] = set()
    for part in (p.strip() for p in text.split(",") if p.strip()):
        key, _, value = part.partition("=")
        key = key.strip().lower()
        if key in given:
            problems.append(Problem("--late-policy", f"{key} is given twice",
                                    f"keep one {key}=... (write it like {EXAMPLE})"))  # fmt: skip
            continue
        given.add(key)
        try:
            settings.update(_policy_part(key, value, part))
        except ValueError as error:
            problems.append(Problem("--late-policy", str(error)))
    return settings, problems


def _policy_part(key: str, value: str, part: str) -> dict[str, object]:
    """The settings one ``key=value`` part of a policy gives (a ValueError if it is wrong)."""
    if key in ("grace", "cutoff"):
        return {key: parse_duration(value, key)}
    if key == "penalty":
        amount, _, period = value.partition("/")
        if period.strip().lower() not in PERIODS:
            raise ValueError(
                f"penalty={value}: say per what, e.g. penalty=10%/day or penalty=2/hour "
                f"({', '.join(PERIODS)})"
            )
        return {"per_period": parse_amount(amount, "penalty"),
                "period": PERIODS[period.strip().lower()]}  # fmt: skip
    if key == "cap":
        return {"cap": parse_amount(value, "cap")}
    raise ValueError(
        f"unknown part {part!r}; write it like {EXAMPLE} (grace, penalty, cap, cutoff; each "
        "optional)"
    )


def parse_duration(text: str, what: str) -> timedelta:
    """``15m``, ``36h``, ``2d`` as a duration of at most `MAX_DURATION`; a clear error naming
    ``what`` otherwise."""
    match = _DURATION.match(text)
    if match is None:
        raise ValueError(f"{what}={text!r}: write a duration like 15m, 36h or 2d")
    seconds = Fraction(match.group(1)) * UNITS[match.group(2)]
    if seconds > MAX_DURATION.total_seconds():
        raise ValueError(
            f"{what}={text.strip()} is longer than a term can use: at most "
            f"{MAX_DURATION.days}d; write e.g. 15m, 36h or 2d"
        )
    return timedelta(seconds=float(seconds))


def parse_amount(text: str, what: str) -> Amount:
    """``10%`` (of the points earned, at most 100 %) or ``2`` (points)."""
    match = _AMOUNT.match(text)
    if match is None:
        raise ValueError(f"{what}={text!r}: write points like 2 or a percentage like 10%")
    amount = Amount(Fraction(match.group(1)), bool(match.group(2)))
    if amount.percent and amount.value > 100:
        raise ValueError(f"{what}={text.strip()}: more than all the points; at most 100%")
    return amount


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
    (None: the grading machine's zone, as it was on that date); a wall-clock time the
    zone skips or shows twice (daylight saving time) is refused with its candidates."""
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
    return _wall_clock(due, zone, what)


def _wall_clock(due: datetime, zone: tzinfo | None, what: str) -> datetime:
    """The one instant the wall-clock time ``due`` names in ``zone`` (None: the machine's)."""
    earlier, later = (_instant(due.replace(fold=fold), zone) for fold in (0, 1))
    if earlier.utcoffset() == later.utcoffset():
        return earlier
    clock = f"the clock of {zone}" if zone is not None else "this machine's clock"
    first, second = sorted((earlier, later), key=lambda moment: moment.astimezone(timezone.utc))
    shown = " or ".join(moment.isoformat(timespec="minutes") for moment in (first, second))
    if _on_clock(first, zone).replace(tzinfo=None, fold=0) == due.replace(fold=0):
        happens = "happens twice on"
    else:  # the clocks jumped over it: its candidates read differently on the clock
        happens = "does not exist on"
        shown = " or ".join(
            _on_clock(moment, zone).isoformat(timespec="minutes") for moment in (first, second)
        )
    raise ValueError(
        f"{what} {due.isoformat(timespec='minutes')} {happens} {clock} (daylight saving time); "
        f"write the one you mean with its offset: {shown}"
    )


def _instant(wall: datetime, zone: tzinfo | None) -> datetime:
    """The instant the wall-clock time ``wall`` (its ``fold`` choosing) names in ``zone``."""
    return wall.replace(tzinfo=zone) if zone is not None else wall.astimezone()


def _on_clock(moment: datetime, zone: tzinfo | None) -> datetime:
    """``moment`` as the clock of ``zone`` (None: the machine's) shows it."""
    return moment.astimezone(timezone.utc).astimezone(zone)


def read_extensions(
    path: Path, due: datetime, zone: tzinfo | None
) -> tuple[dict[str, datetime], list[Problem]]:
    """Each student's own due date from a CSV with a header ``id,extension`` (a duration
    added to the class's due date, e.g. ``2d``) or ``id,due`` (a date and time), and the
    file's mistakes; other columns (a reason, say) are kept out of the way."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no extensions file at {path}")
    columns, lines = read_table(path)
    if "id" not in columns or not {"extension", "due"} & set(columns):
        header = Problem(f"{path}, line 1", "the first line must name the columns",
                         "e.g. 'id,extension,reason' (extension like 2d) or 'id,due' (due like "
                         "2027-03-03T23:59)")  # fmt: skip
        return {}, [header]
    own: dict[str, datetime] = {}
    first_line: dict[str, int] = {}
    problems: list[Problem] = []
    for line in lines:
        where, identifier = f"{path}, line {line.number}", line.cells.get("id", "")
        if line.extra:
            problems.append(too_many_fields(where, line.extra))
        elif not identifier:
            problems.append(Problem(where, "no student id", "write the id first, as in the roster"))
        elif identifier in first_line:
            problems.append(Problem(where, f"{identifier!r} has a second extension (the first "
                                    f"is on line {first_line[identifier]})",
                                    "keep one line per student"))  # fmt: skip
        else:
            first_line[identifier] = line.number
            try:
                own[identifier] = _own_due(line.cells, due, zone, where)
            except ValueError as error:
                problems.append(Problem(where, str(error).removeprefix(f"{where}: ")))
    return own, problems


def _own_due(cells: dict[str, str], due: datetime, zone: tzinfo | None, where: str) -> datetime:
    """One line's due date: the class's plus its extension, or its own due date."""
    if cells.get("due") and cells.get("extension"):
        raise ValueError(
            f"{where}: both an extension ({cells['extension']}) and a due date ({cells['due']}); "
            "give one of them"
        )
    if cells.get("due"):
        return parse_due(cells["due"], zone, f"{where}: due")
    if cells.get("extension"):
        return due + parse_duration(cells["extension"], f"{where}: extension")
    raise ValueError(f"{where}: give an extension (like 2d) or a due date")


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
