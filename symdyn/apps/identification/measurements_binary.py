"""Logs in NumPy's binary formats (symdyn.apps.identification.measurements): no parsing, read at disk speed.

* `.npz` (numpy.savez): arrays t (N,), q (N, NQ), qd and qdd (N, NV; optional as in a CSV log),
  tau (N, NV), float64 or any real type;
* `.npy` (numpy.save): one structured array of N records whose field names are the CSV log's
  column names (t, q1, .., tau1, ..; x_b .. for a floating robot).

Both are loaded with allow_pickle=False: a file never executes code, and an array of Python
objects is refused by name. Before anything is loaded, each array's header (numpy.lib.format) is
read for its shape and type, and a log whose values would take more than `max_bytes`
(measurements.MAX_LOG_BYTES) is refused, so that a header claiming 1e11 records allocates
nothing; of a .npz only the arrays t, q, qd, qdd and tau are read. `read_binary` turns either
into the CSV reader's (header, values) so that the columns are checked by the same code.
"""

from __future__ import annotations

import os
import zipfile
from typing import IO

import numpy as np

from ...errors import SymdynError

__all__ = ["read_binary", "ARRAYS", "size_text"]

#: the arrays of a .npz log
ARRAYS = ("t", "q", "qd", "qdd", "tau")


def size_text(count: float) -> str:
    """A number of bytes as text: 512 B, 3 GiB, 6.5 TiB."""
    for unit, scale in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if count >= scale:
            return f"{count / scale:.3g} {unit}"
    return f"{int(count)} B"


def _header(f: IO[bytes], where: str, what: str, size: int) -> tuple[tuple[int, ...], np.dtype, int]:
    """(shape, dtype, bytes of data after the header) of the .npy data in `f` (`size` bytes in
    all), nothing else read; SymdynError for an array of Python objects."""
    fmt = np.lib.format
    try:
        version = fmt.read_magic(f)
        read = {(1, 0): fmt.read_array_header_1_0, (2, 0): fmt.read_array_header_2_0}.get(version)
        if read is None:
            raise ValueError(f"format version {version[0]}.{version[1]}, not 1.0 or 2.0")
        shape, _, dtype = read(f)
    except (ValueError, OSError, EOFError) as exc:
        raise SymdynError(f"{where}: {what}: cannot read as a NumPy array ({exc})") from None
    if dtype.hasobject:
        raise SymdynError(
            f"{where}: {what} holds Python objects (dtype {dtype}), which symdyn never loads (a pickle "
            "could run code; allow_pickle=False): save the values as numbers"
        )
    return shape, dtype, max(size - f.tell(), 0)


def _complete(where: str, what: str, shape: tuple[int, ...], dtype: np.dtype, available: int) -> None:
    """SymdynError when the data the header promises is not all there (a truncated file)."""
    data = int(np.prod(shape, dtype=object)) * dtype.itemsize
    if available < data:
        raise SymdynError(
            f"{where}: {what}: its header promises {size_text(data)} of values for shape {shape}, "
            f"the file holds {size_text(available)} (truncated?)"
        )


def _bytes(shape: tuple[int, ...], dtype: np.dtype) -> int:
    """The bytes the array takes as loaded, or as float64 values, whichever is larger."""
    count = int(np.prod(shape, dtype=object))
    return count * max(dtype.itemsize, 8 * max(len(dtype.names or ()), 1))


def _check_size(where: str, needed: int, max_bytes: int, what: str) -> None:
    if needed > max_bytes:
        raise SymdynError(
            f"{where}: {what} take {size_text(needed)}, more than a log may hold "
            f"({size_text(max_bytes)}: symdyn.apps.identification.measurements.MAX_LOG_BYTES)"
        )


def read_binary(
    path: str | os.PathLike, columns: dict[str, list[str]], max_bytes: int
) -> tuple[list[str], np.ndarray]:
    """(header, values (N, columns)) of a .npz or .npy log; `columns`: each group's column names
    (measurements.log_columns). SymdynError naming the file and the array when it is not one, or
    when its values would take more than `max_bytes`."""
    where = str(path)
    try:
        if zipfile.is_zipfile(path):
            return _read_npz(path, where, columns, max_bytes)
        with open(path, "rb") as f:
            shape, dtype, available = _header(f, where, "the file", os.fstat(f.fileno()).st_size)
        _check_size(where, _bytes(shape, dtype), max_bytes, f"{shape[0] if shape else 1} records")
        _complete(where, "the file", shape, dtype, available)
        loaded = np.load(path, allow_pickle=False)
    except SymdynError:
        raise
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise SymdynError(f"{where}: cannot read as a NumPy file ({exc})") from None
    except MemoryError:
        raise SymdynError(f"{where}: not enough memory to load it (MemoryError)") from None
    if not isinstance(loaded, np.ndarray) or loaded.dtype.names is None or loaded.ndim != 1:
        raise SymdynError(
            f"{where}: a .npy log is one structured array whose fields are the columns (t, q1, ..); "
            f"this one is {loaded.dtype} of shape {loaded.shape} (or write a .npz of t, q, qd, qdd, tau)"
        )
    header = list(loaded.dtype.names)
    for name in header:
        _real(where, loaded[name], f"field {name}")
    return header, np.column_stack([np.asarray(loaded[name], dtype=np.float64) for name in header])


def _read_npz(path, where: str, columns: dict[str, list[str]], max_bytes: int):
    """The arrays t, q, [qd, qdd,] tau of a .npz, their headers checked before they are loaded."""
    with zipfile.ZipFile(path) as z:
        members = {name.removesuffix(".npy"): name for name in z.namelist() if name.endswith(".npy")}
        headers = {}
        for key in ARRAYS:
            if key in members:
                with z.open(members[key]) as f:
                    headers[key] = _header(f, where, f"array {key}", z.getinfo(members[key]).file_size)
        needed = sum(_bytes(shape, dtype) for shape, dtype, _ in headers.values())
        _check_size(where, needed, max_bytes, "its arrays t, q, qd, qdd, tau")
        for key, header in headers.items():
            _complete(where, f"array {key}", *header)
    with np.load(path, allow_pickle=False) as loaded:
        return _from_arrays(where, {k: loaded[k] for k in ARRAYS if k in members}, columns)


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
