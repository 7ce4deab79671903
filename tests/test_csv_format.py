"""The CSV writer in C (symdyn_csv, templates/c/csv.c.j2) against Python's "%.17g"
(symdyn.apps.simulation.csv_format).

The C writer must give the bytes of Python's `%` formatting for every double: the awkward ones
(negative, -0.0, 0.1, integers, 1e-300, 1e300, subnormals, the largest double, nan, inf),
powers of ten and their neighbours (where the decimal exponent changes), exact ties at the
17th digit (rounded half to even), and random bit patterns over the whole range. Python's
digits are themselves checked to read back as the same double. A trajectory written through
the compiled plant equals its csv_text; without a compiler the Python route is taken.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from cbuild import compilers

import symdyn
from symdyn.apps.simulation.csv_format import csv_bytes, csv_text
from symdyn.apps.simulation.simulate import simulate
from symdyn.errors import SymdynWarning

PLANAR = Path(__file__).resolve().parent.parent / "examples" / "planar_3r.yaml"
pytestmark = pytest.mark.skipif(not compilers(), reason="needs a C compiler")


@pytest.fixture(scope="module")
def plant():
    plant = symdyn.compile(symdyn.load_robot(PLANAR))
    assert plant.backend == "c"
    return plant


def _awkward() -> np.ndarray:
    values = [0.0, -0.0, 0.1, -0.1, 1.0, -1.0, 2.0, -3.0, 7.0, 123456789.0, -987654321.0, 1e-300, -1e-300]
    values += [1e300, -1e300, 5e-324, -5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, 1 / 3, 2 / 3]
    values += [0.5, 1e-5, 1e-4, 9.9999999999999991e-5, 1e16, 1e17, 9.9999999999999984e16, 1e22, 1e23]
    values += [
        2.0**53,
        2.0**53 - 1,
        2.0**127,
        2.0**128,
        -(2.0**64),
        float("nan"),
        float("inf"),
        float("-inf"),
    ]
    return np.array(values)


def _powers_of_ten() -> np.ndarray:
    p = np.array([float(f"1e{k}") for k in range(-323, 309)])
    return np.concatenate([p, np.nextafter(p, 0.0), np.nextafter(p, np.inf), -p])


def _integers_and_ties() -> np.ndarray:
    """2^k, 3^k, 5^k and their halves: many exact ties at the 17th significant digit."""
    ints = np.array(
        [2.0**k for k in range(1024)] + [float(3**k) for k in range(600)] + [float(5**k) for k in range(400)]
    )
    small = np.array([m / 2.0**k for k in range(64) for m in (5, 15, 25, 35, 12345, 99999)])
    return np.concatenate([ints, 1.5 * ints, np.nextafter(ints, np.inf), small, -small])


def _random_bits(count: int) -> np.ndarray:
    rng = np.random.default_rng(16)
    bits = rng.integers(0, 2**64, count, dtype=np.uint64).view(np.float64)
    scaled = rng.standard_normal(count) * 10.0 ** rng.integers(-12, 40, count)
    return np.concatenate([bits, scaled])


CASES = {
    "awkward": _awkward,
    "powers of ten": _powers_of_ten,
    "integers and ties": _integers_and_ties,
    "random": lambda: _random_bits(100_000),
}


@pytest.mark.parametrize("name", CASES)
def test_the_c_writer_gives_the_bytes_of_python(plant, name):
    values = CASES[name]()
    values = np.resize(values, (-(-len(values) // 5), 5))  # five columns, the last row wrapped around
    header = [f"c{k}" for k in range(5)]
    want = csv_text(header, values).encode()
    got = csv_bytes(header, values, plant)
    if got != want:
        pairs = zip(got.split(b"\n"), want.split(b"\n"), strict=True)
        bad = [(g, w) for g, w in pairs if g != w][:3]
        pytest.fail(f"{name}: C and Python differ, e.g. {bad}")


def test_python_digits_read_back_as_the_same_double():
    """The reference itself: "%.17g" of every finite value reads back exactly (what the CSV is for)."""
    values = np.concatenate([v() for v in CASES.values()])
    values = values[np.isfinite(values)]
    text = csv_text(["x"], values[:, None])
    back = np.array([float(line) for line in text.splitlines()[1:]])
    assert np.array_equal(back.view(np.uint64), values.view(np.uint64))  # -0.0 kept too


def test_a_trajectory_writes_its_csv_text(plant, tmp_path):
    traj = simulate(plant, [0.3, -0.2, 0.1], [0.0, 1.0, -2.0], duration=0.05, dt=1e-3)
    assert traj.plant is plant
    text = traj.csv_text()
    assert traj.csv_bytes() == text.encode()
    assert traj.write_csv(tmp_path / "traj.csv").read_bytes() == text.encode()
    assert text.splitlines()[0] == "t,q1,q2,q3,qd1,qd2,qd3" and len(text.splitlines()) == 52


def test_without_a_compiler_the_python_route(monkeypatch):
    monkeypatch.setenv("CC", "no-such-compiler-symdyn")
    monkeypatch.setattr("symdyn.apps.compilation.compile._warned", False)
    with pytest.warns(SymdynWarning, match="times slower"):
        slow = symdyn.compile(symdyn.load_robot(PLANAR))
    assert slow.backend == "numpy"
    values = _awkward().reshape(-1, 1)
    assert csv_bytes(["x"], values, slow) == csv_text(["x"], values).encode()
