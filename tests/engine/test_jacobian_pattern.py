"""Implicit Euler reuses one sparsity pattern and gets what a fresh assembly gets."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import msdlab as msd
from msdlab.engine.backends import choice
from msdlab.engine.backends import numpy as numpy_backend
from msdlab.engine.backends.layout import Layout
from msdlab.engine.dynamics import Dynamics


def shaken_grid(seed: int = 0) -> msd.Body:
    rng = np.random.default_rng(seed)
    body = msd.Body.grid((4, 3, 3), spacing=0.1, stiffness=40.0, neighbours=(1, 2, 3))
    body.positions[:] += rng.normal(scale=0.02, size=body.positions.shape)
    body.velocities[:] = rng.normal(size=body.positions.shape)
    body.springs_as_edges()  # values of their own per spring
    body.set_springs(damping=rng.uniform(0.0, 0.5, body.n_springs))
    body.fixed[[0, 5]] = True
    body.velocities[[0, 5]] = 0.0
    return body


def fresh_jacobians(body: msd.Body, x: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """The blocks of `numpy_backend.spring_jacobians` assembled from scratch (COO to CSR)."""
    dim = body.dim
    d = x[body.edges().a] - x[body.edges().b]
    length = np.linalg.norm(d, axis=1)
    n = d / length[:, None]
    outer = n[:, :, None] * n[:, None, :]
    transverse = np.maximum(0.0, 1.0 - body.edges().rest_lengths / length)
    stiff = body.edges().stiffness[:, None, None] * (
        outer + transverse[:, None, None] * (np.eye(dim) - outer)
    )
    damp = body.edges().damping[:, None, None] * outer
    shape = (x.size, x.size)
    jx, jv = sp.lil_matrix(shape), sp.lil_matrix(shape)
    for s, (a, b) in enumerate(zip(body.edges().a, body.edges().b)):
        for first, second, sign in ((a, a, -1), (b, b, -1), (a, b, 1), (b, a, 1)):
            rows = slice(first * dim, first * dim + dim)
            cols = slice(second * dim, second * dim + dim)
            jx[rows, cols] += sign * stiff[s]
            jv[rows, cols] += sign * damp[s]
    return jx.tocsr(), jv.tocsr()


def fresh_implicit_step(body: msd.Body, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Linearised backward Euler on the free particles, every matrix built from scratch."""
    x, v, dim = body.positions, body.velocities, body.dim
    jx, jv = fresh_jacobians(body, x)
    matrix = sp.diags(np.repeat(body.masses, dim)) - dt * jv - dt * dt * jx
    force, _ = numpy_backend.spring_forces(body, x, v)
    rhs = dt * (force.ravel() + dt * (jx @ v.ravel()))
    free = np.repeat(~body.fixed, dim)
    dv = np.zeros_like(rhs)
    dv[free] = spla.spsolve(matrix.tocsr()[free][:, free].tocsc(), rhs[free])
    v_new = v + dv.reshape(v.shape)
    return x + dt * v_new, v_new


def test_pattern_jacobians_equal_fresh_assembly() -> None:
    body = shaken_grid()
    jx, jv = numpy_backend.spring_jacobians(body, body.positions)
    fresh_x, fresh_v = fresh_jacobians(body, body.positions)
    np.testing.assert_allclose(jx.toarray(), fresh_x.toarray(), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(jv.toarray(), fresh_v.toarray(), rtol=1e-12, atol=1e-12)
    assert jx.has_sorted_indices and jx.has_canonical_format


def test_pattern_is_built_once_and_rebuilt_when_springs_change() -> None:
    body = shaken_grid(1)
    dynamics = Dynamics(body)
    first_x, first_v = dynamics.jacobians(body.positions, body.velocities)
    pattern = dynamics.layout.pattern
    body.positions[:] += 0.01
    second_x, _ = dynamics.jacobians(body.positions, body.velocities)
    assert dynamics.layout.pattern is pattern
    assert second_x.indptr is first_x.indptr is first_v.indptr  # same structure, new values
    assert not np.array_equal(second_x.data, first_x.data)
    body.add_springs([[0, len(body) - 1]], stiffness=5.0)
    third_x, _ = dynamics.jacobians(body.positions, body.velocities)
    assert dynamics.layout.pattern is not pattern
    fresh_x, _ = fresh_jacobians(body, body.positions)
    np.testing.assert_allclose(third_x.toarray(), fresh_x.toarray(), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("kernel", ["numba", "numpy"])
def test_implicit_steps_match_fresh_assembly(kernel: str) -> None:
    dt = 0.02
    expected_body, body = shaken_grid(2), shaken_grid(2)
    sim = msd.Simulation(body, msd.ImplicitEuler(tolerance=1e-13), dt=dt, kernel=kernel)
    for _ in range(3):
        x_new, v_new = fresh_implicit_step(expected_body, dt)
        expected_body.positions[:], expected_body.velocities[:] = x_new, v_new
        sim.step()
        np.testing.assert_allclose(body.positions, expected_body.positions, rtol=0, atol=1e-11)
        np.testing.assert_allclose(body.velocities, expected_body.velocities, rtol=0, atol=1e-9)
    assert np.all(body.velocities[body.fixed] == 0.0)


@pytest.mark.parametrize("shape", [(4, 3, 3), (5, 4)])
def test_each_kernel_sums_the_blocks_a_fresh_assembly_sums(kernel: str, shape: tuple) -> None:
    body = shaken_grid(3)
    if len(shape) == 2:
        body = msd.Body.grid(shape, spacing=0.1, stiffness=40.0, neighbours=(1, 2))
        body.positions[:] += np.random.default_rng(3).normal(scale=0.03, size=(20, 2))
        body.springs_as_edges()  # values of their own per spring
        body.set_springs(slice(None, None, 2), damping=0.3)
    jx, jv = choice.make_kernel(kernel).jacobians(Layout(body), body.positions)
    fresh_x, fresh_v = fresh_jacobians(body, body.positions)
    np.testing.assert_allclose(jx.toarray(), fresh_x.toarray(), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(jv.toarray(), fresh_v.toarray(), rtol=1e-12, atol=1e-12)


def test_coincident_ends_give_an_isotropic_block(kernel: str) -> None:
    """No direction: the stiffness block of a spring of length 0 is k I, its dashpot's 0."""
    body = msd.Body.from_arrays([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[0, 1]], stiffness=7.0)
    body.set_springs(damping=0.5)
    body.positions[1] = body.positions[0]
    jx, jv = choice.make_kernel(kernel).jacobians(Layout(body), body.positions)
    block = 7.0 * np.eye(3)
    np.testing.assert_array_equal(jx.toarray(), np.block([[-block, block], [block, -block]]))
    np.testing.assert_array_equal(jv.toarray(), np.zeros((6, 6)))


@pytest.mark.parametrize("dashpots", [False, True])
def test_implicit_matrix_is_the_sum_of_the_jacobians(dashpots: bool) -> None:
    """M - h_v ∂F/∂v - h_x ∂F/∂x on the pattern's values, a force's Jacobian included."""
    body = shaken_grid(4)
    if not dashpots:
        body.set_springs(damping=0.0)
    dynamics = Dynamics(body, [msd.ViscousDamping(0.3)])
    x, v = body.positions, body.velocities
    matrix, jx = dynamics.implicit_matrix(x, v, 0.02, 0.0004)
    expected_x, expected_v = dynamics.jacobians(x, v)
    expected = sp.diags(np.repeat(body.masses, 3)) - 0.02 * expected_v - 0.0004 * expected_x
    np.testing.assert_allclose(matrix.toarray(), expected.toarray(), rtol=1e-13, atol=1e-13)
    np.testing.assert_array_equal(jx.toarray(), expected_x.toarray())
