"""symdyn.progress: the stages of long work on standard error, after DELAY seconds, as lines in a log
and as tqdm bars on a terminal; --quiet and SYMDYN_QUIET silence them."""

from __future__ import annotations

import importlib
import io
import re
import time
from pathlib import Path

import pytest

from symdyn import progress
from symdyn.apps.compilation.build import SECONDS_PER_BYTE, compile_estimate

cli_main = importlib.import_module("symdyn.cli.main")  # the module (symdyn.cli.main is also its function)

ROGER = Path(__file__).resolve().parent.parent / "examples" / "roger_arm.yaml"
LINE = re.compile(r"symdyn: \d+\.\d s: (.*)")


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def reporting(monkeypatch):
    """Reports on (the suite silences them), at once (no delay), into a stream the test reads."""
    monkeypatch.delenv(progress.QUIET_ENV, raising=False)
    monkeypatch.setattr(progress, "DELAY", 0.0)
    stream = io.StringIO()
    monkeypatch.setattr(progress, "_stream", lambda: stream)
    progress.restart()
    progress.quiet(False)
    yield stream
    progress.quiet(False)


def lines(stream: io.StringIO) -> list[str]:
    return [m.group(1) for m in map(LINE.fullmatch, stream.getvalue().splitlines()) if m]


def test_a_log_gets_one_line_per_stage_nested_stages_named_with_their_parent(reporting):
    with progress.stage("deriving"), progress.stage("M", total=3, unit="family") as advance:
        advance()
    with progress.stage("writing", total=1, unit="file"):
        pass
    progress.finish()
    assert lines(reporting) == ["deriving", "deriving / M (3 families)", "writing (1 file)", "done"]


def test_a_stage_shorter_than_the_delay_says_nothing_and_a_longer_one_says_it_then(reporting, monkeypatch):
    monkeypatch.setattr(progress, "DELAY", 0.3)
    progress.restart()
    with progress.stage("quick"):
        pass
    time.sleep(0.4)  # the timer of "quick" was cancelled: nothing comes late
    assert reporting.getvalue() == ""
    progress.restart()
    with progress.stage("slow"):
        time.sleep(0.6)
    assert lines(reporting) == ["slow"]
    assert 0.3 <= float(reporting.getvalue().split()[1]) < 0.6  # said at the delay, not at the end


def test_quiet_and_the_environment_silence_everything(reporting, monkeypatch):
    progress.quiet()
    with progress.stage("deriving"):
        progress.note("big")
    progress.finish()
    progress.quiet(False)
    monkeypatch.setenv(progress.QUIET_ENV, "1")
    with progress.stage("deriving"):
        progress.note("big")
    progress.finish()
    assert reporting.getvalue() == ""


def test_a_terminal_gets_a_bar_with_the_count(monkeypatch):
    monkeypatch.delenv(progress.QUIET_ENV, raising=False)
    monkeypatch.setattr(progress, "DELAY", 0.0)
    screen = Terminal()
    monkeypatch.setattr(progress, "_stream", lambda: screen)
    progress.restart()
    with progress.stage("common subexpressions", total=4, unit="pass") as advance:
        for _ in range(4):
            time.sleep(0.12)  # tqdm redraws at most every 0.1 s
            advance()
    progress.finish()  # a terminal's bars clear themselves: no 'done' line
    shown = screen.getvalue()
    assert "symdyn: common subexpressions" in shown and "4/4" in shown and "done" not in shown


def test_derive_reports_its_stages_and_quiet_silences_them(reporting, capsys):
    assert cli_main.main(["derive", str(ROGER)]) == 0
    out = capsys.readouterr().out
    said = lines(reporting)
    assert said[0] == f"loading {ROGER}" and said[-1] == "done"
    assert "deriving 'roger_arm' (2 joints, newton-euler)" in said
    assert out.startswith("# roger_arm: 2 joints") and "symdyn:" not in out  # stdout is untouched
    reporting.truncate(0)
    reporting.seek(0)
    assert cli_main.main(["derive", str(ROGER), "--quiet"]) == 0
    assert capsys.readouterr().out == out and reporting.getvalue() == ""


def test_generate_notes_the_size_of_its_c_and_a_build_time(reporting, capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(cli_main, "BIG_C", 1)
    assert cli_main.main(["generate", str(ROGER), "--target", "c", "--out", str(tmp_path)]) == 0
    size = (tmp_path / "roger_arm_dynamics.c").stat().st_size
    note = next(line for line in reporting.getvalue().splitlines() if line.startswith("symdyn: note: "))
    assert note.startswith(f"symdyn: note: {size / 1000:.0f} KB of C in 1 file: a build takes roughly ")
    low, high = map(int, re.search(r"roughly (\d+)-(\d+) s", note).groups())
    assert (low, high) == (
        max(1, round(size * SECONDS_PER_BYTE[0])),
        max(1, round(size * SECONDS_PER_BYTE[1])),
    )


def test_the_estimate_brackets_the_measured_builds():
    """The rates behind compile_estimate, against the builds they were measured on (gcc 12 -O2):
    the PUMA 560's 308 KB in 2.3 s, the Panda's 729 KB in 7.0 s, Solo-12's floating 435 KB in 11.8 s."""
    for size, seconds in ((308_374, 2.26), (729_267, 7.04), (434_570, 11.77)):
        low, high = map(int, re.search(r"(\d+)-(\d+)", compile_estimate(size)).groups())
        assert low <= seconds <= high + 0.5


def test_a_name_with_newlines_and_escapes_stays_on_its_line(reporting):
    """A URDF robot's name may hold a newline or a terminal escape: its stage line stays one line."""
    with progress.stage("deriving 'a\nsymdyn: 0.0 s: done\x1b[2J'"):
        progress.note("x\ny")
    assert reporting.getvalue().splitlines()[0].endswith("deriving 'a\\nsymdyn: 0.0 s: done\\x1b[2J'")
    assert reporting.getvalue().splitlines()[1] == "symdyn: note: x\\ny"


def test_steps_show_on_a_terminal_unless_silenced_or_where_asked_moving_once_per_percent(monkeypatch):
    """symdyn.progress.Steps, the bar of a simulation: by default only on a terminal and not under
    quiet() or SYMDYN_QUIET; shown=True shows it anywhere; 100,000 updates redraw it 101 times."""
    monkeypatch.delenv(progress.QUIET_ENV, raising=False)
    progress.quiet(False)
    screen, log = Terminal(), io.StringIO()
    monkeypatch.setattr(progress, "_stream", lambda: screen)
    assert progress.Steps("simulate", 10).enabled
    progress.quiet()
    assert not progress.Steps("simulate", 10).enabled and progress.Steps("simulate", 10, True).enabled
    progress.quiet(False)
    monkeypatch.setenv(progress.QUIET_ENV, "1")
    assert not progress.Steps("simulate", 10).enabled
    monkeypatch.setattr(progress, "_stream", lambda: log)
    monkeypatch.delenv(progress.QUIET_ENV)
    off = progress.Steps("simulate", 10)
    off.update(5, 0.5)
    off.close()
    assert not off.enabled and log.getvalue() == ""
    bar = progress.Steps("simulate", 100_000, True, until=2.0)
    moves = []
    update = bar._bar.update
    monkeypatch.setattr(bar._bar, "update", lambda k: moves.append(k) or update(k))
    for k in range(1, 100_001):
        bar.update(k, 2e-5 * k)
    bar.close()
    assert len(moves) == 101 and sum(moves) == 100_000  # 0 % .. 100 %
    assert "100%" in log.getvalue() and "t = 2.000 / 2.000 s]\n" in log.getvalue()
