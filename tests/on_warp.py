"""Which engine tests also run on the Warp backend (``kernel="warp"``), on Warp's CPU device
where no GPU is lent: the backend contract, the step and its trace, the energy ledger, the
ground. tests/engine/conftest.py parametrises the engine's tests over the kernels, Warp
among them, and keeps Warp's runs of the tests named here only; the seeds' scenes stepped
whole on the device, and the trampoline's first 0.6 s, run on Warp in
tests/scenes/test_on_warp.py.

Warp's CPU device runs one thread and a host integrator's every call crosses to it, so the
whole engine suite on it would add minutes to CI; the seeds' scenes with contact forces
(trampoline, contact ledger) pass their whole tests on it too (``MSDLAB_KERNEL=warp``), in
about 5 minutes.
"""

from __future__ import annotations

import pytest

# file, or file::test name prefix, relative to the tests folder
ON_WARP = (
    "engine/test_backends.py",
    "engine/test_step_trace.py",
    "engine/test_energy.py::test_ledger",
    "engine/test_energy.py::test_without_the_ledger",
    "engine/test_forces_and_constraints.py::test_ground",
    "engine/test_warp.py",
)


def warp_or_skip(kernel: str) -> str:
    """``kernel``, skipping the test if it is "warp" and Warp is not installed."""
    if kernel == "warp":
        pytest.importorskip("warp")
    return kernel


def keep_warp_runs_named(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Deselect the Warp runs (a ``kernel`` parameter "warp") of the tests not in `ON_WARP`."""
    kept, dropped = [], []
    for item in items:
        on_warp = getattr(item, "callspec", None) and item.callspec.params.get("kernel") == "warp"
        name = item.nodeid.split("tests/", 1)[-1]
        (dropped if on_warp and not name.startswith(ON_WARP) else kept).append(item)
    if dropped:
        config.hook.pytest_deselected(items=dropped)
        items[:] = kept
