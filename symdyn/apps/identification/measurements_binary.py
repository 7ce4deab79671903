"""Logs in NumPy's binary formats (symdyn.apps.measurements): no parsing, read at disk speed.

* `.npz` (numpy.savez): arrays t (N,), q (N, NQ), qd and qdd (N, NV; optional as in a CSV log),
  tau (N, NV), float64 or any real type;
* `.npy` (numpy.save): one structured array of N records whose field names are the CSV log's
  column names (t, q1, .., tau1, ..; x_b .. for a floating robot).

Both are loaded with allow_pickle=False: a file never executes code. `read_binary` turns either
into the CSV reader's (header, values) so that the columns are checked by the same code.
"""

from __future__ import annotations

import os
import zipfile

import numpy as np

from ...errors import SymdynError

__all__ = ["read_binary"]


def read_binary(path: str | os.PathLike, columns: dict[str, list[str]]) -> tuple[list[str], np.ndarray]:
    """(header, values (N, columns)) of a .npz or .npy log; `columns`: each group's column names
    (measurements.log_columns). SymdynError naming the file and the array when it is not one."""
    where = str(path)
    try:
        loaded = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise SymdynError(f"{where}: cannot read as a NumPy file ({exc})") from None
    if isinstance(loaded, np.lib.npyio.NpzFile):
        with loaded:
            return _from_arrays(where, {k: loaded[k] for k in loaded.files}, columns)
    if loaded.dtype.names is None or loaded.ndim != 1:
        raise SymdynError(
            f"{where}: a .npy log is one structured array whose fields are the columns (t, q1, ..); "
            f"this one is {loaded.dtype} of shape {loaded.shape} (or write a .npz of t, q, qd, qdd, tau)"
        )
    header = list(loaded.dtype.names)
    return header, _real(where, np.column_stack([loaded[name] for name in header]), "the fields")


def _real(where: str, a: np.ndarray, what: str) -> np.ndarray:
    """`a` as float64, finite; else SymdynError naming `what`."""
    if not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)):
        raise SymdynError(f"{where}: {what}: {a.dtype} values, not real numbers")
    a = np.asarray(a, dtype=np.float64)
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):
        raise SymdynError(f"{where}: {what}: sample {bad[0][0]} is {a[tuple(bad[0])]}, not a finite number")
    return a


def _from_arrays(where: str, arrays: dict, columns: dict[str, list[str]]) -> tuple[list[str], np.ndarray]:
    """The arrays t, q, [qd, qdd,] tau of a .npz as the columns of a CSV log."""
    if "t" not in arrays:
        raise SymdynError(f"{where}: no array t (a .npz log holds t, q, qd, qdd, tau)")
    t = _real(where, np.asarray(arrays["t"]), "array t")
    if t.ndim != 1:
        raise SymdynError(f"{where}: array t has shape {t.shape}, expected (N,)")
    header, blocks = ["t"], [t[:, None]]
    for head in ("q", "qd", "qdd", "tau"):
        if head not in arrays:
            continue  # the missing columns are reported by the CSV's checks
        a = _real(where, np.asarray(arrays[head]), f"array {head}")
        want = (len(t), len(columns[head]))
        if a.shape != want:
            raise SymdynError(f"{where}: array {head} has shape {a.shape}, expected {want}")
        header += columns[head]
        blocks.append(a)
    return header, np.hstack(blocks)
