"""The run a live view shows, kept frame by frame and written as a table of numbers:
time, the energy ledger, every particle's position and velocity, to CSV or NPZ.
"""

from __future__ import annotations

import io
from collections import deque
from pathlib import Path

import numpy as np

RECORD_BYTES = 64e6  # positions and velocities kept, at most (the oldest frames go first)
FORMATS = ("csv", "npz")
AXES = "xyz"


class Recording:
    """The frames of a run as shown: each frame's time, positions, velocities (N, d) and
    energies (the view's ledger: kinetic, elastic, gravitational, other, what each
    mechanism took out). Holds at most `RECORD_BYTES` of positions and velocities."""

    def __init__(self, particles: int, dim: int, time_unit: str, energy_unit: str) -> None:
        self.units = {"time": time_unit, "energy": energy_unit}
        self.frames: deque[tuple[float, np.ndarray, np.ndarray, dict]] = deque(
            maxlen=max(2, int(RECORD_BYTES // (2 * 8 * particles * dim)))
        )

    def add(self, time: float, x: np.ndarray, v: np.ndarray, energy: dict) -> None:
        """Keep a frame (a copy of the arrays); the same time twice is kept once."""
        if self.frames and self.frames[-1][0] == time:
            return
        self.frames.append((time, x.copy(), v.copy(), energy))

    def columns(self) -> dict[str, np.ndarray]:
        """The run as arrays: time (F,), positions and velocities (F, N, d), and one array
        (F,) per energy: kinetic, elastic, gravitational, other, each mechanism's
        dissipated_<name>, and total (their sum)."""
        frames = tuple(self.frames)  # at once: the stepping thread may add one meanwhile
        if not frames:
            raise ValueError("nothing to export yet: the view has sent no frame")
        times, xs, vs, energy = zip(*frames)
        names = sorted({name for e in energy for name in e["dissipated"]})
        table = {"time": np.array(times), "positions": np.stack(xs), "velocities": np.stack(vs)}
        for name in ("kinetic", "elastic", "gravitational", "other"):
            table[name] = np.array([e[name] for e in energy])
        for name in names:
            table[f"dissipated_{name}"] = np.array([e["dissipated"].get(name, 0.0) for e in energy])
        energies = [table[n] for n in table if n not in ("time", "positions", "velocities")]
        table["total"] = np.sum(energies, axis=0)
        return table

    def npz(self) -> bytes:
        """The columns in NumPy's .npz format, with the units as text arrays."""
        buffer = io.BytesIO()
        units = {f"{name}_unit": np.array(unit) for name, unit in self.units.items()}
        np.savez_compressed(buffer, **self.columns(), **units)
        return buffer.getvalue()

    def csv(self) -> bytes:
        """One row per frame: time, the energies (their units in the header), then x_0,
        y_0, ..., vx_0, vy_0, ... of every particle."""
        table = self.columns()
        x, v = table.pop("positions"), table.pop("velocities")
        frames, particles, dim = x.shape
        names = [f"time ({self.units['time']})"] + [
            f"{name} ({self.units['energy']})" for name in list(table)[1:]
        ]
        names += [f"{AXES[k]}_{i}" for i in range(particles) for k in range(dim)]
        names += [f"v{AXES[k]}_{i}" for i in range(particles) for k in range(dim)]
        values = np.column_stack([*table.values(), x.reshape(frames, -1), v.reshape(frames, -1)])
        buffer = io.StringIO()
        np.savetxt(buffer, values, delimiter=",", header=",".join(names), comments="", fmt="%.17g")
        return buffer.getvalue().encode()

    def write(self, path: str | Path) -> Path:
        """Write the run to ``path``, CSV or NPZ by its suffix."""
        path = Path(path)
        kind = path.suffix.lower().lstrip(".")
        if kind not in FORMATS:
            raise ValueError(
                f"cannot export to {path.name!r}: name a .csv file (a table for a spreadsheet) "
                "or a .npz file (NumPy arrays)"
            )
        path.write_bytes(self.npz() if kind == "npz" else self.csv())
        return path
