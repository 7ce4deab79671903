"""The fast reader of large CSV logs (symdyn.apps.identification.csv_read, pandas' C parser)
against Python's float.

Values of every magnitude written as "%.17g" (and shorter spellings, spaces, CRLF, blank lines,
a subnormal) parse to the doubles float() gives; anything outside that syntax, or a wrong count
of values, gives None, and read_measurements then reads the file the slow way, which names the
line and column (tests/test_identify.py) or reads what Python reads.
"""

from __future__ import annotations

import numpy as np
import pytest

from symdyn.apps.identification import csv_read
from symdyn.apps.identification.measurements import read_measurements

pytest.importorskip("pandas", reason="the ident and test extras install pandas")


def test_values_equal_pythons(tmp_path):
    rng = np.random.default_rng(8)
    values = rng.normal(size=(400, 5)) * 10.0 ** rng.integers(-307, 307, size=(400, 5))
    values[::7, 2] = 0.0
    lines = [",".join(f"{x:.17g}" for x in row) for row in values]
    lines[3] = " 1.5 ,\t-2e3,+.25,7.,-0\r"
    lines[10] = "1,2,3,4,5e-320"  # a subnormal
    want = np.array([[float(c) for c in line.split(",")] for line in lines])
    path = tmp_path / "log.csv"
    path.write_bytes(("\n t,a,b,c,d\n" + "\n".join(lines[:50]) + "\n\n  \n" + "\n".join(lines[50:])).encode())
    assert np.array_equal(csv_read.parse_rows(path, 2, 5), want)
    path.write_bytes(("t,a,b,c,d\n" + "\n".join(lines) + "\n").encode())
    assert np.array_equal(csv_read.parse_rows(path, 1, 5), want)
    path.write_bytes(b"t\n")
    assert csv_read.parse_rows(path, 1, 1).shape == (0, 1)


@pytest.mark.parametrize(
    "row",
    [
        "1,2,inf",
        "1,2,nan",
        "1,2,0x1p3",
        "1,2",
        "1,2,3,4",
        "1,,3",
        "1,2,3,",
        "1,2,'3'",
        "1,2,1_000",
        "1,2,3 4",
        "1;2;3",
    ],
)
def test_anything_else_is_refused(row, tmp_path):
    path = tmp_path / "log.csv"
    path.write_text(f"a,b,c\n0,0,0\n{row}\n0,0,0\n")
    assert csv_read.parse_rows(path, 1, 3) is None


def test_what_pandas_refuses_python_reads_or_names(tmp_path):
    """1_000 is Python's float but not pandas': the slow path reads it; a wrong value is named."""
    path = tmp_path / "m.csv"
    path.write_text("t,q1,qd1,qdd1,tau1\n0,1,2,3,4\n1,5,6,7,1_000\n")
    assert read_measurements(path, 1).tau.tolist() == [[4.0], [1000.0]]
    path.write_text("t,q1,qd1,qdd1,tau1\n0,1,2,3,4\n1,5,6,x,8\n")
    with pytest.raises(Exception, match=r"line 3: not a number in column qdd1: 'x'"):
        read_measurements(path, 1)


def test_without_pandas_numpy_reads_the_file(tmp_path, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas":
            raise ImportError("no pandas")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pandas)
    (tmp_path / "m.csv").write_text("t,q1,qd1,qdd1,tau1\n0,1,2,3,4\n1,5,6,7,8\n")
    assert csv_read.parse_rows(tmp_path / "m.csv", 1, 5) is None
    assert read_measurements(tmp_path / "m.csv", 1).tau.tolist() == [[4.0], [8.0]]
