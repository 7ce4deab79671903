"""Progress of long work, on standard error: which stage a command is in and how long it has run.

A command that has run for DELAY (2) seconds starts to report (a quick one says nothing):

- on a terminal, a tqdm bar per stage, its count when the stage has one (functions generated,
  files compiled), else its elapsed time, cleared when the stage ends;
- elsewhere (a log, a pipe, CI), one line per stage as it starts, `symdyn: 12.3 s: generating C
  (7 functions)`, and a last line `symdyn: 51.0 s: done`.

A run that counts its own steps (a simulation) shows a `Steps` bar instead, at once and to the end,
`symdyn: simulate:  50%|#####     | 1500/3000 [00:01<00:01, t = 1.500 / 3.000 s]`, on a terminal or
wherever its caller asks for it.

Stages nest (a stage inside another is reported with the other's label before its own). Nothing
is reported under `quiet()` (the command line's --quiet) or with the environment variable
SYMDYN_QUIET set to anything but 0 or an empty string; the test suite sets it, and turns the
reporting on where it tests it.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, TextIO

from .errors import one_line

if TYPE_CHECKING:
    from tqdm import tqdm

__all__ = ["DELAY", "QUIET_ENV", "Steps", "stage", "note", "quiet", "finish", "restart"]

#: seconds a command runs before it reports anything
DELAY = 2.0
#: set to anything but 0 or '' to silence every report
QUIET_ENV = "SYMDYN_QUIET"
#: seconds between the refreshes of a terminal bar's elapsed time
_REFRESH = 0.5


class _Run:
    """The state of the running command: when it started, whether it reports, what it said."""

    def __init__(self) -> None:
        self.start = time.monotonic()
        self.silenced = False
        self.said = False
        self.labels: list[str] = []
        self.lock = threading.Lock()


_run = _Run()


def restart() -> None:
    """Start timing a new command (the command line calls it first)."""
    global _run
    silenced = _run.silenced
    _run = _Run()
    _run.silenced = silenced


def quiet(on: bool = True) -> None:
    """Silence (or allow again) every report of this process."""
    _run.silenced = on


def _silent() -> bool:
    return _run.silenced or os.environ.get(QUIET_ENV, "") not in ("", "0")


def _stream() -> TextIO:
    return sys.stderr


def _line(label: str) -> None:
    with _run.lock:
        print(f"symdyn: {time.monotonic() - _run.start:.1f} s: {one_line(label)}", file=_stream(), flush=True)
        _run.said = True


@contextmanager
def stage(label: str, total: int | None = None, unit: str = "step") -> Iterator[Callable[[int], None]]:
    """Report the stage `label` while the block runs; yields advance(k=1), which counts k of the
    stage's `total` steps done (a no-op without a total or when nothing is reported)."""
    full = " / ".join([*_run.labels, label])
    _run.labels.append(label)
    try:
        if _silent():
            yield lambda k=1: None
        elif _stream().isatty():
            with _bar(full, total, unit) as advance:
                yield advance
        else:
            with _lines(full, total, unit):
                yield lambda k=1: None
    finally:
        _run.labels.pop()


@contextmanager
def _lines(label: str, total: int | None, unit: str) -> Iterator[None]:
    """The line of the stage: now when the command has run DELAY s, else at that moment if the
    stage still runs then."""
    text = label if total is None else f"{label} ({total} {_plural(unit, total)})"
    wait = DELAY - (time.monotonic() - _run.start)
    if wait <= 0:
        _line(text)
        yield
        return
    timer = threading.Timer(wait, _line, (text,))
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


def _plural(unit: str, count: int) -> str:
    if count == 1:
        return unit
    if unit.endswith("y"):
        return unit[:-1] + "ies"
    return unit + "es" if unit.endswith(("s", "sh", "ch", "x")) else unit + "s"


def _tqdm(label: str, total: int | None, unit: str, delay: float, leave: bool) -> tqdm:
    """The one kind of bar of this module: `symdyn: LABEL` on standard error, with the count of a
    `total` and its elapsed time, or without a total its elapsed time alone."""
    from tqdm import tqdm

    return tqdm(
        total=total,
        desc=f"symdyn: {one_line(label)}",
        unit=unit,
        delay=delay,
        leave=leave,
        file=_stream(),
        bar_format=None if total is not None else "{desc}: {elapsed}",
    )


@contextmanager
def _bar(label: str, total: int | None, unit: str) -> Iterator[Callable[[int], None]]:
    """A bar shown once the command has run DELAY s, refreshed while the stage runs."""
    bar = _tqdm(label, total, unit, max(0.0, DELAY - (time.monotonic() - _run.start)), leave=False)
    stop = threading.Event()

    def refresh() -> None:
        while not stop.wait(_REFRESH):
            if time.monotonic() - _run.start >= DELAY:
                bar.refresh()
                _run.said = True

    ticker = threading.Thread(target=refresh, daemon=True)
    ticker.start()
    try:
        yield lambda k=1: bar.update(k)
    finally:
        stop.set()
        ticker.join()
        bar.close()


class Steps:
    """The bar of a run of `total` steps that counts them itself (a simulation over `until` seconds
    of simulated time): `symdyn: LABEL:  50%|#####     | 1500/3000 [..., t = 1.500 / 3.000 s]`.

    Shown when `shown` is True; with None, when standard error is a terminal and no report is
    silenced (`quiet()`, SYMDYN_QUIET). It moves at most once per percent (a run of millions of
    steps calls `update` for each), and its last state stays on its line, ended by a newline.
    """

    def __init__(self, label: str, total: int, shown: bool | None = None, until: float | None = None) -> None:
        if shown is None:
            shown = not _silent() and _stream().isatty()
        self.enabled = bool(shown)
        self.total = max(total, 1)
        self.until = until
        self._percent = -1
        self._bar = _tqdm(label, self.total, "step", 0.0, leave=True) if self.enabled else None

    def update(self, done: int, t: float | None = None) -> None:
        """`done` of the steps are done, the simulated time at `t` seconds."""
        if self._bar is None:
            return
        percent = 100 * done // self.total
        if percent == self._percent:
            return
        self._percent = percent
        if t is not None and self.until is not None:
            self._bar.set_postfix_str(f"t = {t:.3f} / {self.until:.3f} s", refresh=False)
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        """End the bar's line (its last state stays)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None


def note(text: str) -> None:
    """`symdyn: note: text` on standard error, now (not after DELAY), unless silenced."""
    if not _silent():
        with _run.lock:
            print(f"symdyn: note: {one_line(text)}", file=_stream(), flush=True)


def finish() -> None:
    """The last line of a command that reported in lines (not on a terminal, whose bars clear)."""
    if _run.said and not _silent() and not _stream().isatty():
        _line("done")
