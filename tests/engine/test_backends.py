"""Every spring kernel computes what the readable numpy kernel computes, method by method.

The numpy kernel (`backends.numpy.NumpyKernel`) is the reference. Each kernel named in
`choice.KERNELS` runs each method of `contract.SpringKernel` on the same
bodies (a cloth built from arrays, grids in 2-D and 3-D, a pinned body, a damped
body) and must give the numpy kernel's results to rounding (`RTOL`; a compiled loop
sums in its own order); its `advance` must give what the numpy kernel's forces,
a = (F + m·g)/m and the update on whole arrays give. A new backend is added to
`KERNELS` and gets all of it.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np
import pytest

import msdlab as msd
from msdlab.engine import equations
from msdlab.engine.backends import choice, contract
from msdlab.engine.backends.layout import Layout
from msdlab.engine.backends.numpy import NumpyKernel

RTOL = 1e-12
REFERENCE = NumpyKernel()


def cloth(n: int = 9, spacing: float = 0.05) -> msd.Body:
    """An n×n cloth from arrays: stretch, shear and bend springs with dashpots, two corners
    pinned, shaken and moving (3-D)."""
    ij = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    index = ij[:, 0] * n + ij[:, 1]
    pairs, stiffness = [], []
    for (di, dj), k in {(1, 0): 400.0, (0, 1): 400.0, (1, 1): 200.0, (1, -1): 200.0}.items():
        for reach, scale in ((1, 1.0), (2, 0.1)) if dj >= 0 and di + dj == 1 else ((1, 1.0),):
            inside = (ij[:, 0] + reach * di < n) & (ij[:, 1] + reach * dj >= 0)
            inside &= ij[:, 1] + reach * dj < n
            pairs.append(np.column_stack([index[inside], index[inside] + reach * (di * n + dj)]))
            stiffness.append(np.full(inside.sum(), k * scale))  # bend springs reach 2 apart
    positions = np.column_stack([ij * spacing, np.zeros(len(ij))])
    fixed = (ij[:, 1] == n - 1) & ((ij[:, 0] == 0) | (ij[:, 0] == n - 1))
    body = msd.Body.from_arrays(
        positions, np.vstack(pairs), masses=0.01, fixed=fixed, stiffness=np.concatenate(stiffness)
    )
    body.set_springs(damping=0.02)
    return shaken(body, seed=1)


def shaken(body: msd.Body, seed: int) -> msd.Body:
    """``body`` with its free particles moved off rest and moving (fixed ones at rest)."""
    rng = np.random.default_rng(seed)
    body.positions[:] += rng.normal(scale=0.01, size=body.positions.shape)
    body.velocities[:] = rng.normal(scale=0.3, size=body.positions.shape)
    body.velocities[body.fixed] = 0.0
    return body


def grid(dim: int) -> msd.Body:
    """A grid with one stiffness per offset and no dashpots (the numba kernel gathers it)."""
    shape, neighbours = ((5, 4, 3), (1, 2, 3)) if dim == 3 else ((7, 5), (1, 2))
    return shaken(msd.Body.grid(shape, spacing=0.1, stiffness=30.0, neighbours=neighbours), 2)


def pinned(dim: int) -> msd.Body:
    """A grid with uniform dashpots and a pinned row, its particles of uneven masses."""
    shape, neighbours = ((4, 4, 3), (1, 2)) if dim == 3 else ((6, 5), (1, 2))
    body = msd.Body.grid(shape, spacing=0.1, stiffness=50.0, neighbours=neighbours, damping=0.2)
    body.fixed[: shape[-1]] = True
    body.masses[:] = np.random.default_rng(3).uniform(0.5, 2.0, len(body))
    return shaken(body, 3)


def damped(dim: int) -> msd.Body:
    """A grid whose springs each have their own stiffness and dashpot (some none)."""
    body = grid(dim)
    rng = np.random.default_rng(4)
    body.springs_as_edges()  # values of their own per spring
    body.set_springs(stiffness=rng.uniform(10.0, 50.0, body.n_springs))
    body.set_springs(damping=np.where(rng.random(body.n_springs) < 0.5, 0.3, 0.0))
    body.fixed[[0, 3]] = True
    body.velocities[[0, 3]] = 0.0
    return body


BODIES: dict[str, Callable[[], msd.Body]] = {
    "cloth": cloth,
    "grid 3-D": lambda: grid(3),
    "grid 2-D": lambda: grid(2),
    "pinned 3-D": lambda: pinned(3),
    "pinned 2-D": lambda: pinned(2),
    "damped 3-D": lambda: damped(3),
    "damped 2-D": lambda: damped(2),
}

# How a kernel is made to use its threads on these small bodies (its own thresholds).
THREADED: dict[str, tuple[str, ...]] = {
    "numba": tuple(
        f"msdlab.engine.backends.numba.kernel.PARALLEL_MIN_{least}"
        for least in ("SPRINGS", "GATHERED", "PARTICLES")
    ),
}


@pytest.fixture(params=[name for name in choice.KERNELS if name != "numpy"])
def kernel(request: pytest.FixtureRequest) -> str:
    """Each kernel of `choice.KERNELS` but the reference itself (this overrides the
    engine's two-kernel run); Warp's where it is installed (the test extra installs it)."""
    if request.param == "warp":
        pytest.importorskip("warp")
    return request.param


@pytest.fixture(params=["one thread", "threads"])
def backend(
    request: pytest.FixtureRequest, kernel: str, monkeypatch: pytest.MonkeyPatch
) -> contract.SpringKernel:
    """The kernel under test, on one thread or made to share even small bodies out."""
    if request.param == "threads":
        if kernel not in THREADED:
            pytest.skip(f"the {kernel} kernel has no threads")
        for setting in THREADED[kernel]:
            monkeypatch.setattr(setting, 0)
    return choice.make_kernel(kernel)


@pytest.fixture(params=list(BODIES))
def body(request: pytest.FixtureRequest) -> msd.Body:
    return BODIES[request.param]()


def assert_close(actual: np.ndarray, expected: np.ndarray) -> None:
    scale = float(np.abs(expected).max(initial=1.0))
    np.testing.assert_allclose(actual, expected, rtol=RTOL, atol=RTOL * scale)


def test_spring_forces(backend: contract.SpringKernel, body: msd.Body) -> None:
    """The forces are added to what ``out`` holds; the largest stretch and the dashpot
    power come by name; a subset of the springs gives its own forces."""
    x, v = body.positions, body.velocities
    out, expected = np.ones_like(x), np.zeros_like(x)
    sums = backend.spring_forces(Layout(body), x, v, out)
    reference = REFERENCE.spring_forces(Layout(body), x, v, expected)
    assert_close(out - 1.0, expected)
    assert sums.stretch == pytest.approx(reference.stretch, rel=RTOL)
    assert sums.power == pytest.approx(reference.power, rel=RTOL, abs=1e-300)
    assert (sums.power > 0.0) == bool(body.edges().damping.any())
    some = body.springs_touching(np.array([1, 5, 6]))
    out, expected = np.zeros_like(x), np.zeros_like(x)
    subset = backend.spring_forces(Layout(body), x, v, out, some)
    reference = REFERENCE.spring_forces(Layout(body), x, v, expected, some)
    assert_close(out, expected)
    assert subset == pytest.approx(reference, rel=RTOL, abs=1e-300)


def test_elastic_energy(backend: contract.SpringKernel, body: msd.Body) -> None:
    x = body.positions
    assert backend.elastic_energy(Layout(body), x) == pytest.approx(
        REFERENCE.elastic_energy(Layout(body), x)
    )
    some = body.springs_touching(np.array([2, 7]))
    expected = REFERENCE.elastic_energy(Layout(body), x, some)
    assert backend.elastic_energy(Layout(body), x, some) == pytest.approx(expected, rel=RTOL)


def test_jacobians(backend: contract.SpringKernel, body: msd.Body) -> None:
    got = backend.jacobians(Layout(body), body.positions)
    expected = REFERENCE.jacobians(Layout(body), body.positions)
    assert_close(got.position.toarray(), expected.position.toarray())
    assert_close(got.velocity.toarray(), expected.velocity.toarray())


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_finite(backend: contract.SpringKernel, body: msd.Body, bad: float) -> None:
    x, v = body.positions.copy(), body.velocities.copy()
    assert backend.finite(x, v) and REFERENCE.finite(x, v)
    v[len(v) // 2, -1] = bad
    assert not backend.finite(x, v) and not REFERENCE.finite(x, v)


def object_update(x: float, v: float, a: float, dt: float) -> tuple[float, float]:
    """An update numba cannot compile (it builds a Python object): it runs on arrays."""
    note = {"why": object()}
    del note
    return msd.SymplecticEuler.update(x, v, a, dt)


UPDATES = {
    "Verlet": (msd.Verlet.update, (0.01,)),
    "SymplecticEuler": (msd.SymplecticEuler.update, ()),
    "ExplicitEuler": (msd.ExplicitEuler.update, ()),
    "not compiled": (object_update, ()),
}


@pytest.mark.parametrize("update", list(UPDATES))
@pytest.mark.parametrize("others", [False, True])
def test_fused_advance(
    backend: contract.SpringKernel, body: msd.Body, update: str, others: bool
) -> None:
    """The fused `advance` is the forces, a = (F + m·g)/m and the update on arrays, with the
    stretch and power of the pass; ``others`` adds forces beside the springs'."""
    function, coefficients = UPDATES[update]
    x, v, dt = body.positions, body.velocities, 1e-3
    field = np.array([0.0, -9.81, 0.0][: body.dim])
    forces = np.random.default_rng(5).normal(size=x.shape) if others else None
    total = np.zeros_like(x)
    sums = REFERENCE.spring_forces(Layout(body), x, v, total)
    total = total + (0.0 if forces is None else forces)
    masses = body.masses[:, None]
    a = equations.acceleration(total + masses * field, masses, ~body.fixed[:, None])
    expected = function(x, v, a, dt, *coefficients)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # numba cannot compile object_update
        step = backend.advance(function, Layout(body), x, v, field, dt, coefficients, forces)
    assert_close(step.x, expected[0])
    assert_close(step.v, expected[1])
    assert step.stretch == pytest.approx(sums.stretch, rel=RTOL)
    assert step.power == pytest.approx(sums.power, rel=RTOL, abs=1e-300)


def test_the_fused_advance_is_its_own_forces_then_the_update_bit_for_bit(
    backend: contract.SpringKernel, body: msd.Body
) -> None:
    """Fusing changes no bit: the kernel's own `spring_forces`, then a = (F + m·g)/m and
    `Verlet.update` on whole arrays give the same new state."""
    x, v, dt = body.positions, body.velocities, 1e-3
    field = np.array([0.0, -9.81, 0.0][: body.dim])
    forces = np.zeros_like(x)
    sums = backend.spring_forces(Layout(body), x, v, forces)
    masses = body.masses[:, None]
    a = equations.acceleration(forces + masses * field, masses, ~body.fixed[:, None])
    expected = msd.Verlet.update(x, v, a, dt, 0.01)
    step = backend.advance(msd.Verlet.update, Layout(body), x, v, field, dt, (0.01,))
    np.testing.assert_array_equal(step.x, expected[0])
    np.testing.assert_array_equal(step.v, expected[1])
    assert (step.stretch, step.power) == sums


def test_damping_work(backend: contract.SpringKernel, body: msd.Body) -> None:
    v_new = np.random.default_rng(6).normal(size=body.velocities.shape)
    arrays = (body.masses, body.velocities, v_new, 0.97)
    assert backend.damping_work(*arrays) == pytest.approx(REFERENCE.damping_work(*arrays), rel=RTOL)


@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_ground_clamp(backend: contract.SpringKernel, body: msd.Body, friction: float) -> None:
    """The same particles are put on the plane (a tilted one, above the middle of the body)
    with the same velocities, and the same energy is booked; fixed ones stay below."""
    normal = np.array([0.2, 1.0, -0.1][: body.dim])
    normal /= np.linalg.norm(normal)
    height = float(np.median(body.positions @ normal))
    rng = np.random.default_rng(8)
    x_old, v_old = body.positions, body.velocities
    x_new, v_new = x_old + 0.01 * rng.normal(size=x_old.shape), rng.normal(size=x_old.shape)
    x_new[body.fixed] = x_old[body.fixed]
    ends = []
    for kernel in (backend, REFERENCE):
        x, v = x_new.copy(), v_new.copy()
        arrays = (x, v, x_old, v_old, body.masses, body.fixed, normal, height, 0.01, friction)
        ends.append((x, v, kernel.ground_clamp(*arrays)))
    (x, v, removed), (x_ref, v_ref, removed_ref) = ends
    assert removed_ref != 0.0 and not np.array_equal(x_ref, x_new)  # the ground acted
    assert_close(x, x_ref)
    assert_close(v, v_ref)
    np.testing.assert_array_equal(x[body.fixed], x_old[body.fixed])
    assert removed == pytest.approx(removed_ref, rel=RTOL)


class MethodUpdate(msd.Integrator):
    """An integrator whose update is an ordinary method (it takes self)."""

    def update(self, x: float, v: float, a: float, dt: float) -> tuple[float, float]:
        return msd.SymplecticEuler.update(x, v, a, dt)

    def step(
        self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: msd.Dynamics
    ) -> tuple[np.ndarray, np.ndarray]:
        return dynamics.advance(self.update, x, v, dt)


def test_an_update_that_is_a_method_says_how_to_compile_it(body: msd.Body) -> None:
    """A method taking self is no plain function: numba cannot compile it. It runs on arrays
    with the same result, and says once that a @staticmethod compiles."""
    sim = msd.Simulation(body.copy(), MethodUpdate(), kernel="numba", max_stretch=None)
    reference = msd.Simulation(body.copy(), msd.SymplecticEuler(), kernel="numpy")
    with pytest.warns(RuntimeWarning, match=r"update MethodUpdate\.update .*@staticmethod"):
        sim.run(steps=3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sim.run(steps=2)
    reference.run(steps=5)
    assert_close(sim.body.positions, reference.body.positions)


def unchanged(x: float, v: float, a: float, dt: float) -> tuple[float, float]:
    """An update that hands the state back as it was."""
    return x, v


@pytest.mark.parametrize("name", choice.KERNELS)
def test_advance_returns_arrays_no_one_else_holds(name: str) -> None:
    """The new state is the backend's own arrays, also from an update that hands x and v
    back: the simulation makes them the body's state uncopied."""
    body = msd.Body.grid((3, 3, 3), spacing=0.1, stiffness=50.0, neighbours=(1, 2))
    x, v = body.positions, body.velocities
    step = choice.make_kernel(name).advance(unchanged, Layout(body), x, v, np.zeros(3), 1e-3, ())
    for new, old in ((step.x, x), (step.v, v)):
        np.testing.assert_array_equal(new, old)
        assert not np.may_share_memory(new, x) and not np.may_share_memory(new, v)
