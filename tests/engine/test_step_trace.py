"""A student with a debugger who steps into `sim.step()` reads physics: one warm step of the
README's jelly cube enters at most 20 distinct msdlab functions, on either kernel."""

from __future__ import annotations

import sys
from pathlib import Path

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
    assert "simulation.Simulation.step" in entered
    assert len(entered) <= MOST, f"{len(entered)} functions: {entered}"
