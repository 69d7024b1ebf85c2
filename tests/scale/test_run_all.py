"""`cluster.run_all`: every call gets its outcome, in order, whatever its worker does."""

from __future__ import annotations

import os
import signal
import time
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import pytest

from msdlab.analysis.cluster import parse_cluster, run_all


def square(x: int) -> int:
    return x * x


def dies_once(x: int, marker: str) -> int:
    """Kill its own worker process the first time it runs."""
    if not Path(marker).exists():
        Path(marker).touch()
        os.kill(os.getpid(), signal.SIGKILL)
    return x * x


def always_dies(x: int) -> int:
    os.kill(os.getpid(), signal.SIGKILL)
    return x


def _one_killer(x: int) -> int:
    return always_dies(x) if x == 1 else square(x)


def kills_beside(x: int, started: str) -> int:
    """Call 0 kills its worker once another call has started (so that one is running when
    the pool breaks); the others take half a second."""
    if x != 0:
        Path(started).touch()
        time.sleep(0.5)
        return x * x
    deadline = time.monotonic() + 10.0
    while not Path(started).exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    return always_dies(x)


def refuses_two(x: int) -> int:
    if x == 2:
        raise ValueError("two is refused")
    return x * x


def fails_once(x: int, marker: str) -> int:
    if not Path(marker).exists():
        Path(marker).touch()
        raise OSError("a passing problem")
    return x * x


@pytest.mark.parametrize("where", ["local:2", "scheduler"])
def test_results_and_errors_come_back_in_the_order_of_the_calls(where, request) -> None:
    spec = request.getfixturevalue("scheduler") if where == "scheduler" else where
    calls = [((x,), {}) for x in range(5)]
    outcomes = run_all(spec, refuses_two, calls, label="squares", retries=1)
    assert outcomes[:2] == [0, 1] and outcomes[3:] == [9, 16]
    assert isinstance(outcomes[2], ValueError) and "two is refused" in str(outcomes[2])


def test_a_worker_that_dies_costs_a_retry_not_a_result(tmp_path: Path) -> None:
    calls = [((x,), {"marker": str(tmp_path / "died")}) for x in range(4)]
    assert run_all("local:2", dies_once, calls, label="dies once") == [0, 1, 4, 9]


def test_a_call_that_always_kills_its_worker_gets_its_error_and_the_rest_their_results():
    calls = [((x,), {}) for x in range(3)]
    outcomes = run_all("local:2", _one_killer, calls, label="killer", retries=1)
    assert outcomes[0] == 0 and outcomes[2] == 4
    assert "process" in str(outcomes[1]).lower(), outcomes[1]


@pytest.mark.parametrize("retries", [0, 1, 2])
def test_calls_running_beside_a_killer_are_not_charged_its_deaths(tmp_path, retries):
    """Each time call 0 kills its worker, call 1 is running in the same pool."""
    calls = [((x,), {"started": str(tmp_path / "started")}) for x in range(3)]
    outcomes = run_all("local:2", kills_beside, calls, label="beside", retries=retries)
    assert isinstance(outcomes[0], BrokenProcessPool)
    assert outcomes[1:] == [1, 4]


def test_a_call_that_raises_is_run_again(tmp_path: Path) -> None:
    calls = [((x,), {"marker": str(tmp_path / "failed")}) for x in range(3)]
    assert run_all("local:1", fails_once, calls, label="fails once") == [0, 1, 4]


@pytest.mark.parametrize("spec", ["local:0", "local:x", "local", ""])
def test_bad_cluster_specs_are_refused(spec: str) -> None:
    with pytest.raises(ValueError, match=r"local:N|scheduler address"):
        parse_cluster(spec)
