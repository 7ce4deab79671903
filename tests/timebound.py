"""Time bounds for the tests of hostile input: a hang fails its test instead of stalling the suite.

`within(seconds)` interrupts the block with SIGALRM; the exception is a BaseException, so that
no `except Exception` of the code under test (the command line's internal-error handler) can
swallow it. `refused(capsys, args)` runs the `symdyn` command in this process within a bound
and returns its one line of error.
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from contextlib import contextmanager

from symdyn.cli.main import main

__all__ = ["TookTooLong", "within", "refused"]


class TookTooLong(BaseException):
    """A block ran past its time bound."""


@contextmanager
def within(seconds: float) -> Iterator[None]:
    """Fail with TookTooLong if the block runs for more than `seconds` (main thread only)."""

    def alarm(signum, frame):
        raise TookTooLong(f"took more than {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def refused(capsys, *args: str, seconds: float = 10) -> str:
    """The one-line error of `symdyn ARGS`, which must exit with status 1 within `seconds`."""
    capsys.readouterr()
    with within(seconds):
        status = main([str(a) for a in args])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert status == 1, err
    assert len(lines) == 1 and lines[0].startswith("symdyn: error: "), err
    return lines[0]
