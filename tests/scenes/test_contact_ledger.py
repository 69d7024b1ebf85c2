"""The energy ledger with contact: bodies at rest on the ground or on walls, and drops that settle.

At rest nothing moves, so no ledger entry may move either; the ground and the
walls only take energy out; and in a drop that settles the balance closes
(initial = now + dissipated + drift) with a drift that shrinks at the
integrator's order.
"""

from __future__ import annotations

import numpy as np
import pytest

from msdlab.scenes import gallery, jelly

ROUNDOFF = 1e-12


def entries(ledger) -> dict[str, np.ndarray]:
    """Every energy column of the ledger (J)."""
    return {k: v for k, v in ledger.as_arrays().items() if k not in ("step", "time")}


def test_a_jelly_cube_resting_on_the_ground_keeps_every_ledger_entry_still():
    sim = jelly.jelly_cube(size=6)
    settling = sim.run(steps=1500, record_every=50).energies
    initial = settling.total[0]
    resting = sim.run(steps=600).energies
    for name, values in entries(resting).items():
        assert np.ptp(values) <= 0.01 * initial, name
    assert np.min(np.diff(settling.dissipated["ground"])) >= -ROUNDOFF * initial
    assert np.min(np.diff(resting.dissipated["ground"])) >= -ROUNDOFF * initial


def drop_and_settle(dt: float) -> np.ndarray:
    """Drift / initial energy of the jelly cube's drop at step dt, over the same 240 time
    units, with the same damping rate (λ = 0.01 per 0.4)."""
    sim = jelly.jelly_cube(size=6, dt=dt, damping=0.01 * dt / 0.4)
    ledger = sim.run(duration=240.0, record_every=5).energies
    assert ledger.dissipated["ground"][-1] > 0.005 * ledger.total[0]  # it landed
    assert np.min(np.diff(ledger.dissipated["ground"])) >= -ROUNDOFF * ledger.total[0]
    return ledger.drift / ledger.total[0]


def test_a_jelly_drop_closes_its_balance_and_the_drift_shrinks_at_second_order():
    """Measured: max |drift| 0.44 %, 0.11 %, 0.028 % of the initial energy at dt = 0.4,
    0.2, 0.1: rates 3.99 and 3.94 per halving, Verlet's order 2."""
    drifts = [np.max(np.abs(drop_and_settle(dt))) for dt in (0.4, 0.2, 0.1)]
    assert drifts[0] <= 0.01
    rates = np.log2(np.array(drifts[:-1]) / np.array(drifts[1:]))
    assert np.all(rates > 1.8), rates


@pytest.mark.parametrize("scene", ["triangle", "wheel", "truss", "mesh"])
def test_bodies_in_hard_walls_settle_with_a_closed_balance_and_walls_never_put_energy_in(scene):
    sim = getattr(gallery, scene)()
    ledger = sim.run(steps=1200, record_every=1).energies
    initial = ledger.total[0]
    assert np.min(np.diff(ledger.dissipated["walls"])) >= -ROUNDOFF * initial
    assert abs(ledger.drift[-1]) <= 0.01 * initial


@pytest.mark.parametrize("scene", ["wheel", "truss", "mesh"])
def test_bodies_resting_on_a_wall_keep_every_ledger_entry_still(scene):
    sim = getattr(gallery, scene)()
    initial = sim.run(steps=1200, record_every=1200).energies.total[0]
    resting = sim.run(steps=600).energies
    for name, values in entries(resting).items():
        assert np.ptp(values) <= 0.01 * initial, name
