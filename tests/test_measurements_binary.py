"""Logs in NumPy's binary formats (symdyn.apps.identification.measurements_binary through read_measurements):
a .npz of t, q, qd, qdd, tau and a structured .npy give the values of the same CSV log exactly;
a wrong array is one line naming the file and the array, and a pickle is never loaded."""

from __future__ import annotations

import numpy as np
import pytest

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
    with pytest.raises(SymdynError, match=r"objects\.npy: cannot read as a NumPy file"):
        read_measurements(tmp_path / "objects.npy", 2)
