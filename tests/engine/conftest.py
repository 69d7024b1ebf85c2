"""Every engine test runs on both CPU kernels, the readable numpy one and the compiled one;
the tests named in `on_warp.ON_WARP` on the Warp backend too."""

from __future__ import annotations

import pytest
from on_warp import keep_warp_runs_named, warp_or_skip


@pytest.fixture(params=["numpy", "numba", "warp"], autouse=True)
def kernel(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """The spring kernel of the test: ``MSDLAB_KERNEL`` is set to it, so it is the default."""
    monkeypatch.setenv("MSDLAB_KERNEL", warp_or_skip(request.param))
    return request.param


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    keep_warp_runs_named(config, items)
