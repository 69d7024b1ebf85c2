"""Both spring kernels compute what the readable `Spring` objects compute, through one interface."""

from __future__ import annotations

import sys

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine import equations
from msdlab.engine.backends import choice
from msdlab.engine.backends import numpy as numpy_backend
from msdlab.engine.backends.layout import Layout
from msdlab.engine.dynamics import Dynamics

RTOL = 1e-12


def deformed_body(dim: int, seed: int = 0) -> msd.Body:
    """A small grid, shaken and moving, with some dashpots and two fixed particles."""
    rng = np.random.default_rng(seed)
    shape = (5, 4, 3) if dim == 3 else (7, 5)
    neighbours = (1, 2, 3) if dim == 3 else (1, 2)
    body = msd.Body.grid(shape, spacing=0.1, stiffness=30.0, neighbours=neighbours)
    body.positions[:] += rng.normal(scale=0.02, size=body.positions.shape)
    body.velocities[:] = rng.normal(size=body.positions.shape)
    body.springs_as_edges()  # values of their own per spring
    body.set_springs(stiffness=rng.uniform(10.0, 50.0, body.n_springs))
    body.masses[:] = rng.uniform(0.5, 2.0, len(body))
    body.set_springs(damping=np.where(rng.random(body.n_springs) < 0.5, 0.3, 0.0))
    body.fixed[[0, 3]] = True
    return body


def per_spring(body: msd.Body) -> tuple[np.ndarray, float, float]:
    """Eq. (1.1) by a Python loop over the readable `Spring.force`, the elastic energy and
    the dashpot power Σ c ((v_a - v_b)·n)², spring by spring."""
    total = np.zeros_like(body.positions)
    energy = power = 0.0
    for spring in body.springs:
        f = spring.force()
        total[spring.a] += f
        total[spring.b] -= f
        energy += spring.energy()
        d = body.positions[spring.a] - body.positions[spring.b]
        rate = np.dot(body.velocities[spring.a] - body.velocities[spring.b], d) / np.linalg.norm(d)
        power += spring.damping * rate**2
    return total, energy, power


def assert_close(actual: np.ndarray | float, expected: np.ndarray | float, scale: float) -> None:
    np.testing.assert_allclose(actual, expected, rtol=RTOL, atol=RTOL * scale)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("threaded", [False, True])
def test_kernel_matches_spring_objects(
    dim: int, threaded: bool, kernel: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    if threaded:
        if kernel != "numba":
            pytest.skip("only the numba kernel has threads")
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_SPRINGS", 0)
        monkeypatch.setattr("msdlab.engine.backends.numba.kernel.PARALLEL_MIN_GATHERED", 0)
    body = deformed_body(dim)
    x, v = body.positions, body.velocities
    springs = choice.make_kernel(kernel)
    assert springs.name == kernel
    forces, energy, power = per_spring(body)
    out = np.ones_like(x)  # the kernel adds to what is there
    stretch, fused_power = springs.spring_forces(Layout(body), x, v, out, None)
    assert_close(out - 1.0, forces, np.abs(forces).max())
    assert stretch == pytest.approx(max(s.length() / s.rest_length for s in body.springs), RTOL)
    assert fused_power == pytest.approx(power, rel=RTOL) and power > 0
    assert springs.elastic_energy(Layout(body), x, None) == pytest.approx(energy, rel=RTOL)
    some = body.springs_touching(np.array([1, 5, 6]))
    by_objects = sum(body.springs[int(s)].energy() for s in some)
    assert springs.elastic_energy(Layout(body), x, some) == pytest.approx(by_objects, rel=RTOL)


def test_public_numpy_functions_match_spring_objects() -> None:
    body = deformed_body(3, seed=1)
    x, v = body.positions, body.velocities
    forces, energy, power = per_spring(body)
    assert_close(numpy_backend.spring_forces(body, x, v)[0], forces, np.abs(forces).max())
    assert numpy_backend.elastic_energy(body, x) == pytest.approx(energy, rel=RTOL)
    dashpots = numpy_backend.NumpyKernel().spring_forces(Layout(body), x, v, np.zeros_like(x)).power
    assert dashpots == pytest.approx(power, rel=RTOL)


@pytest.mark.parametrize("dim", [2, 3])
def test_accelerations_include_forces_and_subsets(dim: int) -> None:
    body = deformed_body(dim, seed=3)
    x, v = body.positions, body.velocities
    g = np.array((0.0, -9.81, 0.0)[:dim])
    dynamics = Dynamics(body, [msd.Gravity(g)])
    forces, _, _ = per_spring(body)
    expected = np.where(body.fixed[:, None], 0.0, forces / body.masses[:, None] + g)
    assert_close(dynamics.acceleration(x, v), expected, np.abs(expected).max())
    particles = np.array([0, 2, 7])
    assert_close(
        dynamics.acceleration_of(particles, x, v), expected[particles], np.abs(expected).max()
    )
    drag = Dynamics(body, [msd.Gravity(g), msd.ViscousDamping(0.4)])  # not a uniform field
    dragged = np.where(body.fixed[:, None], 0.0, expected - 0.4 * v / body.masses[:, None])
    assert_close(drag.acceleration(x, v), dragged, np.abs(expected).max())


def test_kernel_choice(monkeypatch: pytest.MonkeyPatch) -> None:
    body = deformed_body(2)
    monkeypatch.setenv("MSDLAB_KERNEL", "numpy")
    assert choice.default_kernel() == "numpy"
    assert msd.Simulation(body).dynamics.kernel == "numpy"
    monkeypatch.setenv("MSDLAB_KERNEL", "numba")
    assert msd.Simulation(body).dynamics.kernel == "numba"
    assert msd.Simulation(body, kernel="numpy").dynamics.kernel == "numpy"
    monkeypatch.delenv("MSDLAB_KERNEL")
    assert choice.default_kernel() == "numba"
    monkeypatch.setenv("MSDLAB_KERNEL", "fortran")
    with pytest.raises(ValueError, match="MSDLAB_KERNEL must be one of numba, numpy"):
        choice.default_kernel()
    with pytest.raises(ValueError, match="kernel must be one of"):
        msd.Simulation(body, kernel="cuda")


def test_under_a_debugger_the_step_runs_the_readable_equations(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A tracer (what a debugger installs) picks the numpy kernel, whose step calls
    `equations.spring_force` and the integrator's equation (`Verlet.update`), where
    breakpoints stop; ``MSDLAB_KERNEL`` still wins."""
    monkeypatch.delenv("MSDLAB_KERNEL")
    stopped = []

    watched = (equations.spring_force.__code__, msd.Verlet.update.__code__)

    def tracer(frame, event: str, argument: object):
        if event == "call" and frame.f_code in watched:
            stopped.append(frame.f_code.co_qualname)

    sys.settrace(tracer)
    try:
        sim = msd.Simulation(deformed_body(2), msd.Verlet())
        sim.step()
    finally:
        sys.settrace(None)
    assert sim.dynamics.kernel == "numpy"
    assert {"spring_force", "Verlet.update"} <= set(stopped)
    monkeypatch.setenv("MSDLAB_KERNEL", "numba")
    sys.settrace(tracer)
    try:
        assert msd.Simulation(deformed_body(2)).dynamics.kernel == "numba"
    finally:
        sys.settrace(None)


def test_kernel_follows_topology_and_parameter_changes() -> None:
    body = deformed_body(3, seed=5)
    dynamics = Dynamics(body)
    x, v = body.positions, body.velocities
    dynamics.force(x, v)
    body.set_springs(stiffness=body.edges().stiffness * 2.0)  # edits of parameters count at once
    body.add_springs([[0, len(body) - 1]])  # and new springs
    x, v = body.positions, body.velocities
    expected, _, _ = per_spring(body)
    assert_close(dynamics.force(x, v), expected, np.abs(expected).max())


def test_bodies_without_springs() -> None:
    body = msd.Body.from_arrays([[0.0, 1.0], [1.0, 2.0]], velocities=[[1.0, 0.0], [0.0, 0.0]])
    sim = msd.Simulation(body, msd.Verlet(), dt=0.1, forces=[msd.Gravity((0, -1.0))])
    sim.step()
    np.testing.assert_allclose(body.positions, [[0.1, 0.99], [1.0, 1.99]], rtol=1e-14)
    assert sim.dynamics.elastic_energy(body.positions) == 0.0


def test_both_kernels_step_alike() -> None:
    """A few steps with gravity, a ground the body hits, drag, dashpots and fixed particles."""
    runs = {}
    for name in ("numba", "numpy"):
        body = deformed_body(3, seed=4)
        forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground(height=0.12), msd.Drag(0.5)]
        sim = msd.Simulation(body, msd.Verlet(0.01), dt=2e-3, forces=forces, kernel=name)
        runs[name] = (sim.run(steps=15, record_velocities=True), dict(sim.dissipated))
    (fast, fast_booked), (slow, slow_booked) = runs["numba"], runs["numpy"]
    assert slow_booked["ground"] != 0.0  # the ground really acted
    assert_close(fast.positions, slow.positions, 1.0)
    assert_close(fast.velocities, slow.velocities, np.abs(slow.velocities).max())
    for name, energy in slow_booked.items():
        assert fast_booked[name] == pytest.approx(energy, rel=1e-9, abs=1e-12)
