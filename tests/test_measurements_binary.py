"""Logs in NumPy's binary formats (symdyn.apps.identification.measurements_binary through read_measurements):
a .npz of t, q, qd, qdd, tau and a structured .npy give the values of the same CSV log exactly;
a wrong array is one line naming the file and the array, and a pickle is never loaded; sizes are
read from the arrays' headers before anything is allocated (MAX_LOG_BYTES)."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest
from robots import EXAMPLES_DIR
from timebound import refused, within

from symdyn.apps.identification.measurements import read_measurements
from symdyn.errors import SymdynError


def _arrays(N: int = 30) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(1)
    return {"t": np.arange(N) * 0.1, **{k: rng.normal(size=(N, 2)) for k in ("q", "qd", "qdd", "tau")}}


def test_npz_and_structured_npy_equal_the_csv(tmp_path):
    arrays = _arrays()
    names = ["t", *(f"{k}{i}" for k in ("q", "qd", "qdd", "tau") for i in (1, 2))]
    values = np.column_stack(list(arrays.values()))
    lines = [",".join(f"{x:.17g}" for x in row) for row in values]
    (tmp_path / "a.csv").write_text(",".join(names) + "\n" + "\n".join(lines) + "\n")
    np.savez(tmp_path / "a.npz", **arrays)
    record = np.zeros(len(values), dtype=[(name, "f8") for name in reversed(names)])  # any order
    for k, name in enumerate(names):
        record[name] = values[:, k]
    np.save(tmp_path / "a.npy", record)
    for name in ("a.csv", "a.npz", "a.npy"):
        got = read_measurements(tmp_path / name, 2)
        assert np.array_equal(np.column_stack([got.t, got.q, got.qd, got.qdd, got.tau]), values), name


@pytest.mark.parametrize(
    "change,match",
    [
        ({"q": np.zeros((30, 3))}, r"b\.npz: array q has shape \(30, 3\), expected \(30, 2\)"),
        ({"tau": np.full((30, 2), np.nan)}, r"b\.npz: array tau: sample 0 is nan, not a finite number"),
        ({"t": np.zeros((30, 1))}, r"b\.npz: array t has shape \(30, 1\), expected \(N,\)"),
        ({"qd": None}, r"give both qd1\.\.qd2 and qdd1\.\.qdd2, or neither"),
        ({"q": np.array(["a"] * 30)}, r"b\.npz: array q: <U1 values, not real numbers"),
    ],
)
def test_bad_arrays_are_one_line(tmp_path, change, match):
    arrays = {k: v for k, v in {**_arrays(), **change}.items() if v is not None}
    np.savez(tmp_path / "b.npz", **arrays)
    with pytest.raises(SymdynError, match=match):
        read_measurements(tmp_path / "b.npz", 2)


def test_a_plain_or_pickled_npy_is_refused(tmp_path):
    np.save(tmp_path / "plain.npy", np.zeros((5, 9)))
    with pytest.raises(SymdynError, match=r"plain\.npy: a \.npy log is one structured array"):
        read_measurements(tmp_path / "plain.npy", 2)
    np.save(tmp_path / "objects.npy", np.array([{"t": 1}], dtype=object), allow_pickle=True)
    objects = r"objects\.npy: the file holds Python objects \(dtype object\), which symdyn never loads"
    with pytest.raises(SymdynError, match=objects):
        read_measurements(tmp_path / "objects.npy", 2)


def _header_only(shape: tuple, descr="<f8") -> bytes:
    """The .npy header of an array of `shape`, without its data."""
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": descr, "fortran_order": False, "shape": shape})
    return buf.getvalue()


def test_sizes_are_read_from_the_headers_before_anything_is_loaded(tmp_path, capsys):
    """Before: a .npy whose header says (1e11, 9) failed with an internal MemoryError (6.55 TiB),
    a .npz asking for 3 GiB was decompressed; now both are refused from their headers, in a
    second, naming the limit (MAX_LOG_BYTES, 2 GiB)."""
    record = np.dtype(
        [(name, "<f8") for name in ("t", "q1", "q2", "qd1", "qd2", "qdd1", "qdd2", "tau1", "tau2")]
    )
    (tmp_path / "huge.npy").write_bytes(_header_only((10**11,), record.descr))
    scara = str(EXAMPLES_DIR / "scara.yaml")
    line = refused(capsys, "identify", scara, tmp_path / "huge.npy", seconds=5)
    assert line.endswith(
        "huge.npy: 100000000000 records take 6.55 TiB, more than a log may hold "
        "(2 GiB: symdyn.apps.identification.measurements.MAX_LOG_BYTES)"
    )
    with zipfile.ZipFile(tmp_path / "big.npz", "w") as z:
        z.writestr("t.npy", _header_only((3 * 2**30 // 8,)))
    line = refused(capsys, "identify", scara, tmp_path / "big.npz", seconds=5)
    assert line.endswith("big.npz: its arrays t, q, qd, qdd, tau take 3 GiB, more than a log may hold "
                         "(2 GiB: symdyn.apps.identification.measurements.MAX_LOG_BYTES)")  # fmt: skip


def test_truncated_and_object_arrays_are_one_line_and_other_arrays_are_not_read(tmp_path, capsys):
    """A header promising more data than the file holds; an .npz with an object array (before: an
    internal ValueError of np.load); an array other than t, q, qd, qdd, tau is never loaded, even
    one whose header claims a terabyte."""
    (tmp_path / "short.npy").write_bytes(_header_only((100,), [("t", "<f8")]) + bytes(80))
    with within(5), pytest.raises(SymdynError, match=r"the file: its header promises 800 B .* holds 80 B"):
        read_measurements(tmp_path / "short.npy", 2)
    np.savez(tmp_path / "obj.npz", t=np.array([1, "a"], dtype=object), q=np.zeros((2, 2)))
    line = refused(capsys, "identify", EXAMPLES_DIR / "scara.yaml", tmp_path / "obj.npz", seconds=5)
    assert "obj.npz: array t holds Python objects (dtype object), which symdyn never loads" in line
    arrays = _arrays()
    np.savez(tmp_path / "extra.npz", **arrays)
    with zipfile.ZipFile(tmp_path / "extra.npz", "a") as z:
        z.writestr("junk.npy", _header_only((2**40,)))
    got = read_measurements(tmp_path / "extra.npz", 2)
    assert np.array_equal(got.tau, arrays["tau"]) and np.array_equal(got.t, arrays["t"])
