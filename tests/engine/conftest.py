"""Every engine test runs on both spring kernels, the readable numpy one and the compiled one."""

from __future__ import annotations

import pytest


@pytest.fixture(params=["numpy", "numba"], autouse=True)
def kernel(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """The spring kernel of the test: ``MSDLAB_KERNEL`` is set to it, so it is the default."""
    monkeypatch.setenv("MSDLAB_KERNEL", request.param)
    return request.param
