"""Hostile logs for symdyn.apps.identification.measurements (the readers of `symdyn identify` and
`simulate --track`).

A log is a regular file: /dev/zero, a FIFO or a folder is refused at once (reading one might
never end); a CSV whose values would take more than MAX_LOG_BYTES is refused from its count of
lines, before it is parsed; a line before the data longer than MAX_LINE, a field past csv's
limit and times so close that the Savitzky-Golay derivatives overflow are one line each. Every
case runs within a few seconds (tests/timebound.py).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from robots import EXAMPLES_DIR
from timebound import refused, within

from symdyn.apps.identification import measurements
from symdyn.apps.identification.measurements import read_measurements
from symdyn.errors import SymdynError

SCARA = str(EXAMPLES_DIR / "scara.yaml")
HEADER = "t,q1,q2,q3,q4,tau1,tau2,tau3,tau4"


def test_dev_zero_is_refused_at_once(capsys):
    """Before: `symdyn identify scara.yaml /dev/zero` read for ever (no line, no end)."""
    line = refused(capsys, "identify", SCARA, "/dev/zero", seconds=5)
    assert line == (
        "symdyn: error: /dev/zero: not a regular file (a device, FIFO or socket, which may never end): "
        "symdyn reads a log from a file"
    )


def test_fifo_and_folder_are_refused(tmp_path, capsys):
    fifo = tmp_path / "log.csv"
    os.mkfifo(fifo)  # opening it to read would wait for a writer for ever
    assert "log.csv: not a regular file" in refused(capsys, "identify", SCARA, fifo, seconds=5)
    with within(5), pytest.raises(SymdynError, match="is a folder, not a log file"):
        read_measurements(tmp_path, 4)


def test_csv_whose_values_exceed_the_limit_is_refused_before_parsing(tmp_path, monkeypatch):
    """The lines of a CSV larger than MAX_LOG_BYTES / 4 are counted before pandas sees it: the
    limit lowered to 4 KiB, 100 lines of 9 values (7.2 KB as doubles) are refused; 50 are read."""
    monkeypatch.setattr(measurements, "MAX_LOG_BYTES", 4096)
    row = ",".join(["0"] * 9) + "\n"
    path = tmp_path / "long.csv"
    path.write_text(HEADER + "\n" + row * 100)
    with within(5), pytest.raises(SymdynError) as info:
        read_measurements(path, 4)
    assert str(info.value) == (
        f"{path}: 102 lines of 9 values take 7.17 KiB, more than a log may hold "
        "(4 KiB: symdyn.apps.identification.measurements.MAX_LOG_BYTES)"
    )
    path.write_text(HEADER + "\n" + "".join(f"{k * 0.01},0,0,0,0,0,0,0,0\n" for k in range(50)))
    assert len(read_measurements(path, 4).t) == 50


def test_a_line_without_end_and_a_huge_field_are_one_line(tmp_path):
    path = tmp_path / "one.csv"
    path.write_bytes(b"t" * (measurements.MAX_LINE + 10))  # no newline: the header would be all of it
    with within(5), pytest.raises(SymdynError, match=r"one\.csv: line 1 is longer than 1048576 bytes"):
        read_measurements(path, 4)
    path.write_text(HEADER + "\n" + "0," * 8 + "0\n" + "1" * 200_000 + ",0,0,0,0,0,0,0,0\n")
    with within(5), pytest.raises(SymdynError, match=r"one\.csv: line 3: field larger than field limit"):
        read_measurements(path, 4)


def test_savitzky_golay_overflow_is_one_line(tmp_path):
    """Samples 1e-300 s apart: the filter's derivatives of q overflow; refused, not NaN rows."""
    t = np.arange(30) * 1e-300
    rows = np.column_stack([t, np.sin(np.arange(30.0))[:, None] * np.ones((30, 4)), np.zeros((30, 4))])
    path = tmp_path / "fast.csv"
    path.write_text(HEADER + "\n" + "".join(",".join(f"{x:.17g}" for x in r) + "\n" for r in rows))
    with within(10), pytest.raises(SymdynError, match=r"fast\.csv: the Savitzky-Golay derivatives overflow"):
        read_measurements(path, 4)
