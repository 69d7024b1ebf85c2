"""The compiled kernel computes what the readable ones compute: numpy arrays and Spring.force."""

from __future__ import annotations

import numpy as np
import pytest

import msdlab as msd
from msdlab import kernels
from msdlab.dynamics import Dynamics, default_kernel

compiled = pytest.importorskip("msdlab.compiled")

RTOL = 1e-12


def deformed_body(dim: int, seed: int = 0) -> msd.Body:
    """A small grid, shaken and moving, with some dashpots and two fixed particles."""
    rng = np.random.default_rng(seed)
    shape = (5, 4, 3) if dim == 3 else (7, 5)
    neighbours = (1, 2, 3) if dim == 3 else (1, 2)
    body = msd.Body.grid(shape, spacing=0.1, stiffness=30.0, neighbours=neighbours)
    body.positions[:] += rng.normal(scale=0.02, size=body.positions.shape)
    body.velocities[:] = rng.normal(size=body.positions.shape)
    body.stiffness[:] = rng.uniform(10.0, 50.0, body.n_springs)
    body.masses[:] = rng.uniform(0.5, 2.0, len(body))
    body.spring_damping[:] = np.where(rng.random(body.n_springs) < 0.5, 0.3, 0.0)
    body.fixed[[0, 3]] = True
    return body


def per_spring_forces(body: msd.Body) -> np.ndarray:
    """Eq. (1.1) by a Python loop over the readable `Spring.force`."""
    total = np.zeros_like(body.positions)
    for spring in body.springs:
        f = spring.force()
        total[spring.a] += f
        total[spring.b] -= f
    return total


def assert_close(actual: np.ndarray | float, expected: np.ndarray | float, scale: float) -> None:
    np.testing.assert_allclose(actual, expected, rtol=RTOL, atol=RTOL * scale)


@pytest.mark.parametrize("dim", [2, 3])
def test_forces_match_numpy_kernel_and_spring_objects(dim: int) -> None:
    body = deformed_body(dim)
    x, v = body.positions, body.velocities
    expected, stretch = kernels.spring_forces(body, x, v)
    fast = np.zeros_like(x)
    fast_stretch, power = compiled.CompiledKernels().add_spring_forces(body, x, v, fast)
    scale = np.abs(expected).max()
    assert_close(fast, expected, scale)
    assert_close(per_spring_forces(body), expected, scale)
    assert fast_stretch == pytest.approx(stretch, rel=RTOL)
    assert power == pytest.approx(kernels.dashpot_power(body, x, v), rel=RTOL)


@pytest.mark.parametrize("dim", [2, 3])
def test_threaded_blocks_match_one_thread(dim: int) -> None:
    body = deformed_body(dim, seed=1)
    x, v = body.positions, body.velocities
    arrays = (
        body.spring_a.astype(np.int32),
        body.spring_b.astype(np.int32),
        body.stiffness,
        body.rest_lengths,
        body.spring_damping,
    )
    serial, threaded = np.zeros_like(x), np.ones_like(x)
    stretch, power = compiled._spring_forces_serial(x, v, *arrays, serial)
    partial = np.empty((3, *x.shape))  # four blocks: more blocks than threads is allowed
    threaded_sums = compiled._spring_forces_parallel(x, v, *arrays, partial, threaded)
    assert_close(threaded - 1.0, serial, np.abs(serial).max())
    assert threaded_sums[0] == stretch
    assert threaded_sums[1] == pytest.approx(power, rel=RTOL)
    power = compiled._dashpot_power_serial(x, v, *arrays[:2], arrays[4])
    assert compiled._dashpot_power_parallel(x, v, *arrays[:2], arrays[4], 4) == pytest.approx(
        power, rel=RTOL
    )
    energy = compiled._elastic_energy_serial(x, *arrays[:4])
    assert compiled._elastic_energy_parallel(x, *arrays[:4], 4) == pytest.approx(energy, rel=RTOL)


@pytest.mark.parametrize("dim", [2, 3])
def test_energies_and_power_match(dim: int) -> None:
    body = deformed_body(dim, seed=2)
    x, v = body.positions, body.velocities
    fast = Dynamics(body, kernel="numba")
    some = body.springs_touching(np.array([1, 5, 6]))
    by_objects = sum(body.springs[int(s)].energy() for s in some)
    assert fast.elastic_energy(x) == pytest.approx(kernels.elastic_energy(body, x), rel=RTOL)
    assert fast.elastic_energy(x, some) == pytest.approx(by_objects, rel=RTOL)
    assert fast.dashpot_power(x, v) == pytest.approx(kernels.dashpot_power(body, x, v), rel=RTOL)
    assert fast.dashpot_power(x, v) > 0


@pytest.mark.parametrize("dim", [2, 3])
def test_accelerations_match_including_subsets(dim: int) -> None:
    body = deformed_body(dim, seed=3)
    x, v = body.positions, body.velocities
    g = (0.0, -9.81, 0.0)[:dim]
    fast = Dynamics(body, [msd.Gravity(g)], kernel="numba")
    slow = Dynamics(body, [msd.Gravity(g)], kernel="numpy")
    expected = slow.acceleration(x, v)
    assert_close(fast.acceleration(x, v), expected, np.abs(expected).max())
    assert np.all(fast.acceleration(x, v)[body.fixed] == 0.0)
    assert fast.max_stretch == pytest.approx(slow.max_stretch, rel=RTOL)
    particles = np.array([0, 2, 7])
    assert_close(
        fast.acceleration_of(particles, x, v),
        slow.acceleration_of(particles, x, v),
        np.abs(expected).max(),
    )


class SlowVerlet(msd.Verlet):
    """A subclass may change `step`, so it never gets the compiled update."""

    def step(
        self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: Dynamics
    ) -> tuple[np.ndarray, np.ndarray]:
        x_new, v_new = super().step(x, v, dt, dynamics)
        return x_new + 1.0, v_new


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize(
    "integrator",
    [msd.Verlet(), msd.Verlet(damping=0.05), msd.SymplecticEuler(), msd.ExplicitEuler()],
    ids=repr,
)
def test_compiled_update_is_the_readable_step(dim: int, integrator: msd.Integrator) -> None:
    """The fused compiled update computes exactly what the integrator class's `step` says."""
    body = deformed_body(dim, seed=6)
    x, v = body.positions, body.velocities
    forces = [msd.Gravity((0.0, -9.81, 0.0)[:dim])]
    fast = Dynamics(body, forces, kernel="numba")
    x_new, v_new, power = fast.compiled_step(integrator, x, v, 1e-3)
    for kernel in ("numba", "numpy"):
        readable = Dynamics(body, forces, kernel=kernel)
        x_ref, v_ref = integrator.step(x, v, 1e-3, readable)
        assert_close(x_new, x_ref, np.abs(x_ref).max())
        assert_close(v_new, v_ref, np.abs(v_ref).max())
        assert fast.max_stretch == pytest.approx(readable.max_stretch, rel=RTOL)
    x_ref, v_ref = integrator.step(x, v, 1e-3, Dynamics(body, forces, kernel="numba"))
    np.testing.assert_array_equal(x_new, x_ref)  # same kernel: the same bits
    np.testing.assert_array_equal(v_new, v_ref)
    assert power == pytest.approx(kernels.dashpot_power(body, x, v), rel=RTOL)


def test_no_compiled_update_for_other_integrators() -> None:
    body = deformed_body(2)
    dynamics = Dynamics(body, kernel="numba")
    x, v = body.positions, body.velocities
    for integrator in (SlowVerlet(), msd.VelocityVerlet(), msd.RK4(), msd.ImplicitEuler()):
        assert dynamics.compiled_step(integrator, x, v, 1e-3) is None
    assert Dynamics(body, kernel="numpy").compiled_step(msd.Verlet(), x, v, 1e-3) is None
    start = body.positions.copy()
    msd.Simulation(body, SlowVerlet(), dt=1e-3, kernel="numba").step()
    assert np.all(body.positions[~body.fixed] > start[~body.fixed] + 0.5)  # its own step ran


INTEGRATORS = [
    msd.ExplicitEuler(),
    msd.Verlet(),
    msd.Verlet(damping=0.05),
    msd.SymplecticEuler(),
    msd.VelocityVerlet(),
    msd.RK4(),
    msd.ImplicitEuler(),
]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("integrator", INTEGRATORS, ids=repr)
def test_simulation_steps_match(dim: int, integrator: msd.Integrator) -> None:
    """A few steps with gravity, a ground the body hits, drag, dashpots and fixed particles."""
    runs = {}
    for kernel in ("numba", "numpy"):
        body = deformed_body(dim, seed=4)
        g = (0.0, -9.81, 0.0)[:dim]
        forces = [msd.Gravity(g), msd.Ground(height=0.12), msd.Drag(0.5)]
        sim = msd.Simulation(body, integrator, dt=2e-3, forces=forces, kernel=kernel)
        trajectory = sim.run(steps=15, record_velocities=True)
        runs[kernel] = (trajectory, dict(sim.dissipated))
    (fast, fast_booked), (slow, slow_booked) = runs["numba"], runs["numpy"]
    assert slow_booked["ground"] != 0.0  # the ground really acted
    assert_close(fast.positions, slow.positions, 1.0)
    assert_close(fast.velocities, slow.velocities, np.abs(slow.velocities).max())
    for name, energy in slow_booked.items():
        assert fast_booked[name] == pytest.approx(energy, rel=1e-9, abs=1e-12)
    for column, values in slow.energies.as_arrays().items():
        scale = np.abs(slow.energies.total).max()
        assert_close(fast.energies.as_arrays()[column], values, scale)


def test_kernel_choice(monkeypatch: pytest.MonkeyPatch) -> None:
    body = deformed_body(2)
    monkeypatch.setenv("MSDLAB_KERNEL", "numpy")
    assert default_kernel() == "numpy"
    assert msd.Simulation(body).dynamics.kernel == "numpy"
    monkeypatch.setenv("MSDLAB_KERNEL", "numba")
    assert msd.Simulation(body).dynamics.kernel == "numba"
    assert msd.Simulation(body, kernel="numpy").dynamics.kernel == "numpy"
    monkeypatch.setenv("MSDLAB_KERNEL", "fortran")
    with pytest.raises(ValueError, match="MSDLAB_KERNEL must be one of numba, numpy"):
        default_kernel()
    with pytest.raises(ValueError, match="kernel must be one of"):
        msd.Simulation(body, kernel="cuda")


def test_kernel_follows_topology_and_parameter_changes() -> None:
    body = deformed_body(3, seed=5)
    dynamics = Dynamics(body, kernel="numba")
    x, v = body.positions, body.velocities
    dynamics.force(x, v)
    body.stiffness[:] *= 2.0  # edits of parameters count at once
    body.add_springs([[0, len(body) - 1]])  # and new springs
    x, v = body.positions, body.velocities
    expected, _ = kernels.spring_forces(body, x, v)
    assert_close(dynamics.force(x, v), expected, np.abs(expected).max())


@pytest.mark.parametrize("kernel", ["numba", "numpy"])
def test_bodies_without_springs(kernel: str) -> None:
    body = msd.Body.from_arrays([[0.0, 1.0], [1.0, 2.0]], velocities=[[1.0, 0.0], [0.0, 0.0]])
    sim = msd.Simulation(body, msd.Verlet(), dt=0.1, forces=[msd.Gravity((0, -1.0))], kernel=kernel)
    sim.step()
    np.testing.assert_allclose(body.positions, [[0.1, 0.99], [1.0, 1.99]], rtol=1e-14)
    assert sim.dynamics.elastic_energy(body.positions) == 0.0
