"""Connecting to a Dask distributed scheduler, for grading and sweeps that outgrow one machine.

``ADDRESS`` is a running scheduler (``tcp://host:8786``); ``local:N`` starts a
`LocalCluster` of N single-threaded worker processes on this machine. Dask is
the optional extra ``msdlab[cluster]``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

INSTALL = "pip install 'msdlab[cluster]'"


def parse_cluster(spec: str) -> tuple[str | None, int]:
    """``local:N`` → (None, N); anything else → (the scheduler address, 0)."""
    spec = spec.strip()
    if spec.startswith("local:"):
        count = spec.removeprefix("local:")
        if not count.isdigit() or int(count) < 1:
            raise ValueError(f"--cluster local:N needs N >= 1 worker processes, got {spec!r}")
        return None, int(count)
    if not spec or spec.startswith("local"):
        raise ValueError(f"--cluster takes a scheduler address or local:N, got {spec!r}")
    return spec, 0


@contextlib.contextmanager
def connect(spec: str) -> Iterator[Any]:
    """A `dask.distributed.Client` for ``spec`` (see the module docstring), closed on exit."""
    address, workers = parse_cluster(spec)
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise RuntimeError(f"--cluster needs Dask distributed: {INSTALL}") from None
    if address is not None:
        with Client(address) as client:
            yield client
        return
    # One task per worker process; no dashboard; no memory monitor (the work runs in
    # child processes with their own limits, which the nanny would not see anyway).
    with (
        LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            memory_limit=0,
        ) as cluster,
        Client(cluster) as client,
    ):
        yield client
