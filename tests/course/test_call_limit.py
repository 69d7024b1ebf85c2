"""`call_limit`: a limited call gives back the timer it found (pytest-timeout's)."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

from msdlab.course.call_limit import CallTimedOut, forgive, limited, time_limit

HANGS_AFTER_A_LIMITED_CALL = """
import time

from msdlab.course.call_limit import limited


def quick():
    return 1


def test_hangs_after_a_limited_call():
    assert limited(quick, 30.0, "task1.py")() == 1
    time.sleep(120)
"""


def test_a_check_that_hangs_after_a_limited_call_is_stopped_by_pytest_timeout(tmp_path):
    check = tmp_path / "test_hang.py"
    check.write_text(HANGS_AFTER_A_LIMITED_CALL)
    command = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", str(check)]
    options = ["-o", "timeout=2", "-o", "timeout_method=signal", "-o", "addopts="]
    result = subprocess.run(
        command + options, cwd=tmp_path, capture_output=True, text=True, timeout=100
    )
    assert result.returncode == 1, result.stdout + result.stderr
    assert "Timeout" in result.stdout and "1 failed" in result.stdout


def _outer_alarm(signum: int, frame: object) -> None:
    raise AssertionError("the outer timer went off")


@pytest.fixture
def outer_timer():
    """An outer timer of 50 s, as pytest-timeout's signal method sets one."""
    previous = signal.signal(signal.SIGALRM, _outer_alarm)
    signal.setitimer(signal.ITIMER_REAL, 50.0)
    yield
    signal.setitimer(signal.ITIMER_REAL, 0)
    signal.signal(signal.SIGALRM, previous)


def test_the_outer_timer_and_handler_are_restored_with_the_time_they_have_left(outer_timer):
    def expire():
        raise CallTimedOut("inner")

    with pytest.raises(CallTimedOut), time_limit(0.2, expire):
        time.sleep(5)
    left, _ = signal.getitimer(signal.ITIMER_REAL)
    assert 40.0 < left < 50.0
    assert signal.getsignal(signal.SIGALRM) is _outer_alarm


def test_a_limited_call_that_times_out_fails_at_once_until_forgiven(outer_timer):
    def endless():
        while True:
            time.sleep(0.01)

    call = limited(endless, 0.2, "task1.py")
    with pytest.raises(CallTimedOut, match=r"task1.py: endless did not return within 0.2 s"):
        call()
    with pytest.raises(CallTimedOut):
        call()  # at once: no second wait
    forgive()
    assert signal.getitimer(signal.ITIMER_REAL)[0] > 40.0


def test_an_inner_limit_longer_than_the_outer_one_leaves_the_outer_in_charge(outer_timer):
    def expire():
        raise CallTimedOut("inner")

    with time_limit(100.0, expire):
        assert signal.getsignal(signal.SIGALRM) is _outer_alarm
