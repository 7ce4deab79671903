"""The C parser of large CSV logs (symdyn.apps.csv_read) against numpy.loadtxt and Python's float.

Values of every magnitude written as "%.17g" (and shorter spellings, spaces, CRLF, blank lines)
parse to the doubles float() gives, in one part and cut into several parts parsed by threads;
anything outside the plain decimal syntax, or a wrong count of values, gives None (the caller
then reads the file the slow way, which names the line and column).
"""

from __future__ import annotations

import numpy as np
import pytest

from symdyn.apps import csv_read
from symdyn.apps.build import find_compiler

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="needs a C compiler")


def test_values_equal_pythons_in_one_part_and_in_threads(monkeypatch):
    rng = np.random.default_rng(8)
    values = rng.normal(size=(400, 5)) * 10.0 ** rng.integers(-307, 307, size=(400, 5))
    values[::7, 2] = 0.0
    lines = [",".join(f"{x:.17g}" for x in row) for row in values]
    lines[3] = " 1.5 ,\t-2e3,+.25,7.,-0\r"
    lines[10] = "1,2,3,4,5e-320"  # a subnormal
    text = ("t,a,b,c,d\n" + "\n".join(lines[:50]) + "\n\n  \n" + "\n".join(lines[50:])).encode()
    start = text.index(b"\n") + 1
    want = np.array([[float(c) for c in line.split(",")] for line in lines])
    assert np.array_equal(csv_read.parse_rows(text, start, 5, threads=1), want)
    monkeypatch.setattr(csv_read, "PART_BYTES", 64)
    for threads in (2, 3, 8):
        assert np.array_equal(csv_read.parse_rows(text, start, 5, threads=threads), want)
    assert csv_read.parse_rows(text + b"\n", start, 5, threads=3).shape == (400, 5)
    plain = ("t,a,b,c,d\n" + "\n".join(lines)).encode()  # no blank line: the parts fill one array
    for end in (b"", b"\n"):
        assert np.array_equal(csv_read.parse_rows(plain + end, start, 5, threads=3), want)
    assert csv_read.parse_rows(b"t\n", 2, 1).shape == (0, 1)


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
def test_anything_else_is_refused(row):
    text = f"a,b,c\n0,0,0\n{row}\n0,0,0\n".encode()
    assert csv_read.parse_rows(text, 6, 3, threads=1) is None


def test_without_the_parser_the_caller_reads_the_file_itself(tmp_path, monkeypatch):
    """A cache that cannot be written (or a failing compiler) is no error: parse_rows gives None
    and read_measurements reads the file with numpy.loadtxt."""
    from symdyn.apps import cache
    from symdyn.apps.measurements import read_measurements
    from symdyn.errors import SymdynError

    def refuse(*args):
        raise SymdynError("the symdyn cache cannot be written")

    monkeypatch.setattr(csv_read, "_LIBRARY", [])
    monkeypatch.setattr(cache, "get_or_build", refuse)
    assert csv_read.parse_rows(b"a\n1\n", 2, 1) is None
    (tmp_path / "m.csv").write_text("t,q1,qd1,qdd1,tau1\n0,1,2,3,4\n1,5,6,7,8\n")
    assert read_measurements(tmp_path / "m.csv", 1).tau.tolist() == [[4.0], [8.0]]
