"""A student with a debugger who steps into `sim.step()` reads physics: one warm step of the
README's jelly cube enters at most 20 distinct msdlab functions, on either kernel; and the
springs are walked once a step: the energy ledger takes the dashpots' power from the pass
that summed their forces."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import msdlab as msd

PACKAGE = Path(msd.__file__).resolve().parent
# the graded checks' guards on engine entry points (msdlab.course.delegation), which a
# course test earlier in the same process may have installed, are not the engine's step
COURSE = PACKAGE / "course"
MOST = 20


def functions_entered(sim: msd.Simulation) -> list[str]:
    """The distinct msdlab Python functions one `sim.step()` enters, in order."""
    seen: dict[str, None] = {}

    def profile(frame, event: str, argument: object) -> None:
        code = frame.f_code
        path = Path(code.co_filename)
        if event == "call" and path.is_relative_to(PACKAGE) and not path.is_relative_to(COURSE):
            where = path.relative_to(PACKAGE).with_suffix("")
            seen.setdefault(f"{'.'.join(where.parts)}.{code.co_qualname}")

    sys.setprofile(profile)
    try:
        sim.step()
    finally:
        sys.setprofile(None)
    return list(seen)


def test_a_step_of_the_jelly_cube_enters_few_functions(kernel: str) -> None:
    cube = msd.Body.grid((8, 8, 8), spacing=0.1, stiffness=5000.0, neighbours=(1, 2, 3))
    sim = msd.Simulation(
        cube,
        msd.Verlet(damping=0.01),
        dt=1e-3,
        forces=[msd.Gravity((0, -9.81, 0)), msd.Ground(height=0.0)],
        kernel=kernel,
        ledger=True,
    )
    sim.run(steps=3)  # warm: compiled, and resting on the ground
    entered = functions_entered(sim)
    print(f"{len(entered)} functions entered by one step ({kernel} kernel):", *entered, sep="\n  ")
    assert "engine.simulation.simulation.Simulation.step" in entered
    assert len(entered) <= MOST, f"{len(entered)} functions: {entered}"


def damped_cloth() -> msd.Body:
    """A 12×12 cloth of stretch and shear springs with dashpots, two corners pinned."""
    n, spacing = 12, 0.05
    ij = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    index = ij[:, 0] * n + ij[:, 1]
    pairs = []
    for di, dj in ((1, 0), (0, 1), (1, 1), (1, -1)):
        inside = (ij[:, 0] + di < n) & (ij[:, 1] + dj >= 0) & (ij[:, 1] + dj < n)
        pairs.append(np.column_stack([index[inside], index[inside] + di * n + dj]))
    positions = np.column_stack([ij * spacing, np.zeros(len(ij))])
    fixed = (ij[:, 1] == n - 1) & ((ij[:, 0] == 0) | (ij[:, 0] == n - 1))
    body = msd.Body.from_arrays(
        positions, np.vstack(pairs), masses=0.01, fixed=fixed, stiffness=200.0, damping=0.02
    )
    body.velocities[:] = np.random.default_rng(3).normal(0.0, 0.1, body.velocities.shape)
    return body


def test_the_ledger_books_the_dashpots_from_the_pass_over_the_springs(kernel: str) -> None:
    body = damped_cloth()
    sim = msd.Simulation(
        body, msd.SymplecticEuler(), dt=1e-3, forces=[msd.Gravity((0, 0, -9.81))], kernel=kernel
    )
    sim.run(steps=3)
    x, v = body.positions.copy(), body.velocities.copy()
    before = sim.dissipated["dashpot"]
    entered = functions_entered(sim)
    print(f"one step of a damped cloth ({kernel} kernel):", *entered, sep="\n  ")
    assert "engine.dynamics.Dynamics.powers" not in entered  # the ledger's own pass: none
    expected = (
        sim.dynamics.springs.spring_forces(sim.dynamics.layout, x, v, np.zeros_like(x)).power
        * sim.dt
    )
    assert sim.dissipated["dashpot"] - before == pytest.approx(expected, rel=1e-12)
    assert expected > 0.0


class CopyingEuler(msd.Integrator):
    """Symplectic Euler that steps from copies of the state: no pass at the body's arrays."""

    def step(self, x, v, dt, dynamics):
        return dynamics.advance(msd.SymplecticEuler.update, x.copy(), v.copy(), dt)


@pytest.mark.parametrize("integrator", [msd.SymplecticEuler, CopyingEuler])
def test_the_ledger_books_each_force_at_the_state_the_step_starts_from(kernel, integrator):
    """The dashpots and a viscous force are booked at their power at the step's start, from
    the integrator's own pass there, or, if it took none there, from a pass of the ledger's."""
    body = damped_cloth()
    drag = msd.ViscousDamping(0.002)
    sim = msd.Simulation(body, integrator(), dt=1e-3, forces=[drag], kernel=kernel)
    sim.run(steps=2)
    x, v = body.positions.copy(), body.velocities.copy()
    before = dict(sim.dissipated)
    sim.step()
    free = ~body.fixed
    viscous = drag.coefficient * np.sum(v[free] ** 2) * sim.dt
    dashpot = (
        sim.dynamics.springs.spring_forces(sim.dynamics.layout, x, v, np.zeros_like(x)).power
        * sim.dt
    )
    assert sim.dissipated["viscous"] - before["viscous"] == pytest.approx(viscous, rel=1e-12)
    assert sim.dissipated["dashpot"] - before["dashpot"] == pytest.approx(dashpot, rel=1e-12)


PDB_SCRIPT = """
import msdlab as msd
cube = msd.Body.grid((4, 4, 4), spacing=0.1, stiffness=500.0, neighbours=(1, 2))
sim = msd.Simulation(cube, msd.Verlet(0.01), dt=1e-3, forces=[msd.Gravity((0, -9.81, 0))])
sim.step()
print("kernel before:", sim.dynamics.kernel)
breakpoint()
sim.step()
"""


def test_a_breakpoint_set_after_building_stops_in_spring_force(tmp_path: Path) -> None:
    """``breakpoint()`` after the simulation is built and has stepped on the compiled
    kernel: a breakpoint set there in `equations.spring_force` stops at the next step."""
    script = tmp_path / "debug_me.py"
    script.write_text(PDB_SCRIPT)
    commands = "import msdlab.engine.equations\nbreak msdlab.engine.equations.spring_force\n"
    commands += "continue\nwhere\nquit\n"
    env = {key: value for key, value in os.environ.items() if key != "MSDLAB_KERNEL"}
    env["PYTHONBREAKPOINT"] = "pdb.set_trace"
    done = subprocess.run(
        [sys.executable, str(script)],
        input=commands,
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    assert "kernel before: numba" in done.stdout, done.stdout + done.stderr
    stop = done.stdout.split("kernel before: numba", 1)[1]
    assert "equations.py" in stop and "spring_force()" in stop, done.stdout
    assert "simulation.py" in stop  # the stop is inside sim.step()


def test_a_step_traced_after_building_runs_the_readable_equations(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """While a trace function is set (what a debugger does), a simulation that asked for no
    kernel steps on the numpy kernel; untraced again, on the one it chose."""
    monkeypatch.delenv("MSDLAB_KERNEL")
    cube = msd.Body.grid((4, 4, 4), spacing=0.1, stiffness=500.0, neighbours=(1, 2))
    sim = msd.Simulation(cube, msd.Verlet(0.01), dt=1e-3, forces=[msd.Gravity((0, -9.81, 0))])
    chosen = sim.dynamics.kernel
    called: set[str] = set()

    def tracer(frame, event: str, argument: object) -> None:
        if event == "call":
            called.add(f"{Path(frame.f_code.co_filename).name}:{frame.f_code.co_name}")

    pinned = msd.Simulation(cube.copy(), msd.Verlet(0.01), dt=1e-3, kernel="numba")
    sys.settrace(tracer)
    try:
        sim.step()
        pinned.step()
    finally:
        sys.settrace(None)
    assert sim.dynamics.kernel == "numpy"
    assert "equations.py:spring_force" in called and "integrators.py:update" in called
    assert pinned.dynamics.kernel == "numba"  # asked for: kept under a debugger
    sim.step()
    assert sim.dynamics.kernel == chosen
