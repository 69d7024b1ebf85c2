"""The Warp backend's own promises, on Warp's CPU device where no GPU is lent: whole steps
run on the device and agree with the numba backend's; the state lives there and crosses to
the host once per state asked for; a student's update compiles for Warp in float64 as
written, or the run says why it runs on the host; "auto" picks Warp only on a GPU; float32
drifts by a stated amount. (The contract's methods: tests/engine/test_backends.py.)"""

from __future__ import annotations

import ctypes
import subprocess
import sys
import warnings

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine.backends import choice

wp = pytest.importorskip("warp")


@pytest.fixture
def kernel() -> str:
    """Every test here is about the Warp backend (no run per engine kernel)."""
    return "warp"


def falling_cube(kernel: str, n: int = 6) -> msd.Simulation:
    """A damped jelly cube with dashpots and a pinned corner row, dropped on the ground."""
    shape, neighbours = (n, n, n), (1, 2, 3)
    cube = msd.Body.grid(shape, spacing=0.1, stiffness=3000.0, neighbours=neighbours, damping=0.2)
    cube.positions[:, 1] += 0.1
    cube.fixed[:2] = True
    forces = [msd.Gravity((0, -9.81, 0)), msd.Ground(height=0.05, friction=0.3)]
    return msd.Simulation(cube, msd.Verlet(damping=0.01), dt=1e-3, forces=forces, kernel=kernel)


def counted(sim: msd.Simulation) -> list[int]:
    """Counts the backend's whole device steps (``calls[0]``) from now on."""
    calls = [0]
    backend = sim.dynamics.springs
    step = backend.step

    def counting(*arguments: object) -> object:
        calls[0] += 1
        return step(*arguments)

    backend.step = counting
    return calls


def test_whole_steps_run_on_the_device_and_agree_with_numba() -> None:
    """Gravity, the ground with friction, dashpots, pins and Verlet's λ: every step runs
    whole on the device, and positions, velocities and every ledger entry agree with the
    numba backend's to rounding (the gather adds in its own order)."""
    warp, numba = falling_cube("warp"), falling_cube("numba")
    calls = counted(warp)
    runs = [sim.run(steps=300, record_every=100) for sim in (warp, numba)]
    assert calls[0] == 300
    np.testing.assert_allclose(warp.body.positions, numba.body.positions, rtol=0, atol=1e-12)
    np.testing.assert_allclose(warp.body.velocities, numba.body.velocities, rtol=0, atol=1e-9)
    assert warp.dissipated.keys() == numba.dissipated.keys()
    for name, energy in numba.dissipated.items():
        assert warp.dissipated[name] == pytest.approx(energy, rel=1e-11), name
    np.testing.assert_allclose(runs[0].energies.total, runs[1].energies.total, rtol=1e-11)
    assert numba.dissipated["ground"] > 0 and numba.dissipated["dashpot"] > 0


def test_the_state_lives_on_the_device_and_crosses_once_per_state_asked_for() -> None:
    """`state` copies the device's state to new host arrays once, and hands the same ones out
    until the next step; the body adopts them uncopied; an edit of the body in place
    between two calls is where the next step starts (`load` copies it again)."""
    sim = falling_cube("warp", n=3)
    backend = sim.dynamics.springs
    sim.step()
    first = backend.state()
    assert backend.state() is first
    assert first[0] is sim.body.positions and first[1] is sim.body.velocities
    reference = falling_cube("numba", n=3)
    reference.step()
    for body in (sim.body, reference.body):
        body.positions[5, 1] += 0.01  # in place, in the array the backend handed out
    sim.step()
    reference.step()
    np.testing.assert_allclose(sim.body.positions, reference.body.positions, rtol=0, atol=1e-13)
    run = sim.run(steps=30, record_every=10)
    assert backend.state()[0] is sim.body.positions
    np.testing.assert_array_equal(run.positions[-1], sim.body.positions)


def copies(monkeypatch: pytest.MonkeyPatch, sim: msd.Simulation) -> dict[str, int]:
    """Counts, from now on, the copies of x and v between the host and the device: "down",
    a state buffer read to the host (``wp.array.numpy``); "up", host arrays written into a
    state buffer or into the scratch arrays the contract's methods copy x and v into
    (``wp.array.assign``)."""
    backend, counts = sim.dynamics.springs, {"down": 0, "up": 0}
    read, write = wp.array.numpy, wp.array.assign

    def held(array: object) -> bool:
        scratch = [backend._scratch.get(name) for name in ("x", "v")]
        return any(array is other for other in (*backend._state, *scratch))

    def counted_read(array: wp.array) -> np.ndarray:
        counts["down"] += held(array)
        return read(array)

    def counted_write(array: wp.array, source: object) -> None:
        counts["up"] += held(array)
        write(array, source)

    monkeypatch.setattr(wp.array, "numpy", counted_read)
    monkeypatch.setattr(wp.array, "assign", counted_write)
    return counts


def test_a_public_step_copies_x_and_v_once_to_the_host(monkeypatch: pytest.MonkeyPatch) -> None:
    """The state stays on the device: each `sim.step()` reads x and v back once (the body's
    new arrays) and copies nothing up, as the body holds what the device holds."""
    sim = falling_cube("warp", n=3)
    sim.step()  # the first step copies the body's state up
    counted = copies(monkeypatch, sim)
    for _ in range(5):
        sim.step()
    assert counted == {"down": 2 * 5, "up": 0}


@pytest.mark.parametrize("sync", ["step", "frame"])
def test_a_recorded_frame_copies_x_and_v_once(monkeypatch: pytest.MonkeyPatch, sync: str) -> None:
    """A recorded frame reads x and v back once; its energies (the springs' forces for the
    velocity at the positions, the elastic energy) are computed from the device's state,
    not from copies of the frame sent up again."""
    sim = falling_cube("warp", n=3)
    sim.step()
    counted = copies(monkeypatch, sim)
    run = sim.run(steps=30, record_every=10, sync=sync)
    assert counted == {"down": 2 * 3, "up": 0}
    reference = falling_cube("numba", n=3)
    reference.step()
    expected = reference.run(steps=30, record_every=10)
    np.testing.assert_allclose(run.energies.total, expected.energies.total, rtol=1e-11)


def test_edits_of_the_body_between_steps_are_copied_up_and_seen(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """An edit in place of the arrays the backend handed out (a particle dragged, a velocity
    set, a pin) is where the next step starts: x and v go up once, the pins too."""
    sim, reference = falling_cube("warp", n=3), falling_cube("numba", n=3)
    for each in (sim, reference):
        each.step()
    counted = copies(monkeypatch, sim)
    for body in (sim.body, reference.body):
        body.positions[5, 1] += 0.01  # dragged
        body.velocities[6] = 0.0
        body.fixed[7] = True  # pinned where it is
    pinned = sim.body.positions[7].copy()
    for each in (sim, reference):
        each.step()
    assert counted == {"down": 2, "up": 2}
    np.testing.assert_array_equal(sim.body.positions[7], pinned)
    np.testing.assert_array_equal(sim.body.velocities[7], 0.0)
    np.testing.assert_allclose(sim.body.positions, reference.body.positions, rtol=0, atol=1e-13)
    np.testing.assert_allclose(sim.body.velocities, reference.body.velocities, atol=1e-10)


def student_update(x: float, v: float, a: float, dt: float, damping: float) -> tuple[float, float]:
    """Eq. (1.4) as a student writes it: bare float literals and a power of an int."""
    new = (2.0 - damping) * x - (1 - damping) * (x - v * dt) + a * dt**2
    return new, (new - x) / dt


class StudentVerlet(msd.Integrator):
    """A student's integrator: an update function and a step through `Dynamics.advance`."""

    update = staticmethod(student_update)

    def step(
        self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: msd.Dynamics
    ) -> tuple[np.ndarray, np.ndarray]:
        return dynamics.advance(self.update, x, v, dt, 0.01)

    def update_step(self) -> tuple[object, tuple[float, ...]]:
        return self.update, (0.01,)


class StudentVerletAdvancing(StudentVerlet):
    """The same, stepping only through `Dynamics.advance` (no whole steps on the device)."""

    def update_step(self) -> None:
        return None


@pytest.mark.parametrize("whole", [True, False], ids=["whole steps", "advance"])
def test_a_students_update_with_bare_float_literals_compiles_in_float64(whole: bool) -> None:
    """``(2.0 - damping) * x`` is float32 to Warp as written; the backend types the student's
    numbers as Python does (float64): it compiles, says nothing, and steps as the numpy
    kernel does, to rounding; with or without whole steps on the device."""
    integrator = StudentVerlet() if whole else StudentVerletAdvancing()
    sims = []
    for kernel in ("warp", "numpy"):
        body = msd.Body.grid((4, 3, 3), spacing=0.1, stiffness=400.0, damping=0.1)
        body.velocities[:] = np.random.default_rng(2).normal(0.0, 0.2, body.velocities.shape)
        sims.append(msd.Simulation(body, integrator, dt=1e-3, kernel=kernel))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for sim in sims:
            sim.run(steps=50, record_every=50)
    np.testing.assert_allclose(sims[0].body.positions, sims[1].body.positions, rtol=0, atol=1e-14)


def not_for_warp(x: float, v: float, a: float, dt: float) -> tuple[float, float]:
    """An update Warp cannot compile: it calls numpy, which Warp does not know."""
    speed = v + dt * a
    return x + np.multiply(dt, speed), speed


def test_an_update_warp_cannot_compile_says_why_and_where_and_runs_on_the_host() -> None:
    """The run warns once, naming the update, its file and line, and Warp's reason; it then
    steps on the host with the numpy kernel's result."""
    sims = []
    for kernel in ("warp", "numpy"):

        class OnHost(msd.SymplecticEuler):
            update = staticmethod(not_for_warp)

        body = msd.Body.grid((3, 3), spacing=0.1, stiffness=100.0)
        body.velocities[:, 0] = 0.1
        sims.append(msd.Simulation(body, OnHost(), dt=1e-3, kernel=kernel))
    line = not_for_warp.__code__.co_firstlineno
    with pytest.warns(RuntimeWarning, match=rf"not_for_warp \(.*test_warp\.py, line {line}\).*"):
        sims[0].run(steps=5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # said once
        sims[0].run(steps=5)
    sims[1].run(steps=10)
    np.testing.assert_allclose(sims[0].body.positions, sims[1].body.positions, rtol=0, atol=1e-15)


def test_auto_picks_warp_on_a_gpu_and_numba_elsewhere(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(choice, "gpu_present", lambda: False)
    assert choice.make_kernel("auto").name == "numba"
    monkeypatch.setenv("MSDLAB_KERNEL", "auto")
    assert msd.Simulation(msd.Body.grid((2, 2), spacing=0.1)).dynamics.kernel == "numba"
    monkeypatch.setattr(choice, "gpu_present", lambda: True)
    assert choice.make_kernel("auto").name == "warp"
    with pytest.raises(ValueError, match="kernel must be one of numba, numpy, warp, auto"):
        choice.make_kernel("cuda")


def test_auto_without_a_driver_says_nothing_and_leaves_warp_unloaded() -> None:
    """Where NVIDIA's driver library does not load, ``kernel="auto"`` is numba without a word
    on stderr: Warp, whose start-up would say it found no driver, is not even imported."""
    try:
        ctypes.CDLL("libcuda.so.1")
        pytest.skip("this machine has NVIDIA's driver")
    except OSError:
        pass
    code = (
        "import sys; from msdlab.engine.backends import choice; "
        "print(choice.make_kernel('auto').name, 'warp' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert (done.stdout.split(), done.stderr) == (["numba", "False"], "")


def test_float32_on_request_drifts_by_a_stated_amount(monkeypatch: pytest.MonkeyPatch) -> None:
    """``MSDLAB_WARP_PRECISION=float32``: the falling cube's 300 steps (landing, with friction)
    stay within 50 µm of float64's positions and each ledger entry within 5·10⁻⁴ of its
    own (measured: 16 µm; 1.2·10⁻⁴ for the dashpots, 4·10⁻⁵ for Verlet's λ, 9·10⁻⁵ for the
    ground), and the energy balance closes as well (relative drift 5.9·10⁻⁴ both)."""
    double = falling_cube("warp")
    monkeypatch.setenv("MSDLAB_WARP_PRECISION", "float32")
    single = falling_cube("warp")
    assert single.dynamics.springs.dtype == np.float32
    runs = [sim.run(steps=300, record_every=300) for sim in (double, single)]
    np.testing.assert_allclose(single.body.positions, double.body.positions, rtol=0, atol=5e-5)
    for name, energy in double.dissipated.items():
        assert single.dissipated[name] == pytest.approx(energy, rel=5e-4), name
    drifts = [run.energies.relative_drift() for run in runs]
    assert drifts[1] == pytest.approx(drifts[0], rel=0.05)
    monkeypatch.setenv("MSDLAB_WARP_PRECISION", "half")
    with pytest.raises(ValueError, match="MSDLAB_WARP_PRECISION must be float64 or float32"):
        falling_cube("warp")


def test_a_captured_frame_is_its_steps() -> None:
    """`WarpKernel.frame`: steps replayed as one captured sequence (a CUDA graph on a GPU),
    each step's sums in a row of their own, read once, give the state and sums of the same
    steps taken one at a time; an odd frame leaves the other state buffer in front."""
    framed, stepped = falling_cube("warp", n=4), falling_cube("warp", n=4)
    for sim in (framed, stepped):
        sim.dynamics.springs.load(sim.body.positions, sim.body.velocities)
    plan = framed._device_plan()
    rows = [framed.dynamics.springs.frame(7, *plan) for _ in range(2)]
    sums = [stepped.dynamics.springs.step(*stepped._device_plan()) for _ in range(14)]
    for sim in (framed, stepped):
        sim.body.store_state(*sim.dynamics.springs.state())
    np.testing.assert_array_equal(framed.body.positions, stepped.body.positions)
    np.testing.assert_array_equal(framed.body.velocities, stepped.body.velocities)
    expected = [[s.stretch, s.power, s.damping, s.ground, not s.finite] for s in sums]
    np.testing.assert_array_equal(np.vstack(rows), expected)


def test_a_run_synced_per_frame_is_the_run_synced_per_step() -> None:
    """``sync="frame"``: the steps between two recorded frames run as one captured frame;
    the frames, the ledger and the final state are those of the run synced every step."""
    framed, stepped = falling_cube("warp", n=4), falling_cube("warp", n=4)
    runs = [framed.run(steps=45, record_every=10, sync="frame"), stepped.run(45, record_every=10)]
    np.testing.assert_array_equal(runs[0].steps, runs[1].steps)
    np.testing.assert_array_equal(runs[0].positions, runs[1].positions)
    np.testing.assert_array_equal(runs[0].energies.total, runs[1].energies.total)
    assert framed.dissipated == stepped.dissipated
    assert (framed.time, framed.step_count) == (stepped.time, stepped.step_count)


def test_a_frame_that_blows_up_stops_at_the_step_that_did() -> None:
    """A frame whose steps blow up is stepped again from its start, one step at a time: the
    run stops at the same step with the same state as a run synced every step."""
    results = []
    for sync in ("frame", "step"):
        body = msd.Body.grid((4, 4), spacing=0.1, stiffness=1e4)
        body.velocities[5] = (3.0, -2.0)
        sim = msd.Simulation(body, msd.ExplicitEuler(), dt=2e-3, kernel="warp")
        with pytest.raises(msd.SimulationDiverged) as error:
            sim.run(steps=5000, record_every=500, sync=sync)
        results.append((sim.step_count, sim.body.positions.copy(), error.value))
    assert results[0][0] == results[1][0] > 0
    np.testing.assert_array_equal(results[0][1], results[1][1])
    with pytest.raises(ValueError, match='sync must be "step" or "frame"'):
        sim.run(steps=1, sync="graph")


def with_default(x: float, v: float, a: float, dt: float, damping: float = 0.0) -> tuple:
    """An update with a default coefficient (the backend would pass 0 in its place)."""
    return x + dt * v, v + dt * a


def counting_update(x: float, v: float, a: float, dt: float, *coefficients: float) -> tuple:
    """An update taking its coefficients as *args (Warp's functions take a fixed number)."""
    return x + dt * v, v + dt * a


@pytest.mark.parametrize(
    ("update", "reason"),
    [
        (
            staticmethod(lambda x, v, a, dt: (x + dt * v, v + dt * a)).__func__,
            "not written with def",
        ),
        (with_default, "default arguments"),
        (counting_update, r"\*args"),
        (len, "source of len cannot be read"),
    ],
)
def test_what_warp_cannot_compile_is_named(update: object, reason: str) -> None:
    """A student's update Warp cannot take as written is refused with a reason, and then
    runs on the host (`test_an_update_warp_cannot_compile_...`)."""
    from msdlab.engine.backends.warp.update import NotCompiled, typed_source

    with pytest.raises(NotCompiled, match=reason):
        typed_source(update)


def test_the_sums_of_a_gpu_add_up_in_bins_to_those_of_one() -> None:
    """The step's sums added into bins, as on a GPU (particle i into bin i mod 7 here), then
    reduced: the same trajectory and the same ledger, to rounding, as one bin."""
    from msdlab.engine.backends.warp import WarpKernel

    sims = [falling_cube("warp"), falling_cube("warp")]
    sims[1].dynamics.chosen = sims[1].dynamics.springs = WarpKernel("cpu", bins=7)
    for sim in sims:
        sim.run(steps=200, record_every=100)
    np.testing.assert_array_equal(sims[0].body.positions, sims[1].body.positions)
    for name, energy in sims[0].dissipated.items():
        assert sims[1].dissipated[name] == pytest.approx(energy, rel=1e-12), name
