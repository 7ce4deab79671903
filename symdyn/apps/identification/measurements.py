"""Measured logs for identification and tracking: t, q, [qd, qdd,] tau of a fixed or floating robot.

A log is a CSV file with a header naming its columns (any order, extra columns ignored), or the
same values in NumPy's binary formats:

* fixed base (n joints): t, q1..qn, optionally qd1..qdn and qdd1..qddn, and tau1..taun;
* floating base (symdyn.model.free_flyer, docs/floating-base.md): the NQ = 7 + n configuration
  columns x_b y_b z_b qx_b qy_b qz_b qw_b q1..qn, the NV = 6 + n velocity columns
  vx_b vy_b vz_b wx_b wy_b wz_b qd1..qdn (required: a quaternion is not differentiated column by
  column), optionally the NV accelerations ax_b ay_b az_b dwx_b dwy_b dwz_b qdd1..qddn, and the NV
  efforts fx_b fy_b fz_b mx_b my_b mz_b tau1..taun (the wrench on the base in the base frame,
  zero in free flight, then the joint efforts) - the columns `symdyn simulate` writes;
* `.npz`: arrays t (N,), q (N, NQ), qd and qdd (N, NV; optional as in the CSV), tau (N, NV);
  `.npy`: one structured array whose field names are the CSV's column names.

The CSV's numbers are parsed by pandas' C parser when pandas is installed
(symdyn.apps.identification.csv_read;
the `ident` extra installs it), else by numpy.loadtxt; a file both refuse is read again line by
line (Python's csv and float) for a message naming the line and column, or for its values when
Python reads what they do not (1_000). Missing velocities and accelerations of a fixed-base log are estimated
from q by a Savitzky-Golay filter (scipy.signal.savgol_filter; Savitzky and Golay, 1964): a
polynomial of degree SG_ORDER fitted by least squares to each window of SG_WINDOW samples (odd),
whose value and first two derivatives at the window's centre replace q, qd and qdd; a floating
log without accelerations gets qdd as the filter's derivative of qd (v lives in a vector space,
the base's part in the base frame; q and qd stay as measured). The samples must then be evenly
spaced in t.

Limits, checked before anything large is allocated: a log is a regular file (a device such as
/dev/zero, a FIFO or a socket is refused: it may never end); its values (N samples x columns, 8
bytes each) take at most MAX_LOG_BYTES, which a binary log's headers tell before it is loaded and
a CSV's count of lines before it is parsed (counted only when the file exceeds MAX_LOG_BYTES / 4
bytes, since a value takes at least two characters, "0,").
"""

from __future__ import annotations

import csv
import os
import stat
import warnings
from array import array
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import SymdynError
from ...model.free_flyer_names import (
    BASE_ACCELERATION_NAMES,
    BASE_POSITION_NAMES,
    BASE_VELOCITY_NAMES,
    BASE_WRENCH_NAMES,
)
from .csv_read import parse_rows

__all__ = [
    "Measurements",
    "log_columns",
    "read_measurements",
    "differentiate",
    "needs_scipy",
    "SG_WINDOW",
    "SG_ORDER",
    "MAX_LOG_BYTES",
]

#: Savitzky-Golay window (samples, odd) and polynomial degree for qd and qdd from q
SG_WINDOW = 21
SG_ORDER = 4
#: the most bytes a log's values may take (N samples x columns x 8): 2 GiB, e.g. 9 million samples
#: of the Panda's 29 columns
MAX_LOG_BYTES = 2 * 2**30
#: the longest line before the header (blank lines) or of the header itself (bytes)
MAX_LINE = 2**20


@dataclass
class Measurements:
    """N samples: times t (N,), positions q (N, NQ), velocities qd, accelerations qdd, torques tau (N, NV)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    differentiated: bool = False  # qd and qdd (or qdd alone, floating) were estimated (Savitzky-Golay)


def log_columns(n: int, floating: bool = False) -> dict[str, list[str]]:
    """The column names of each group of a log (t, q, qd, qdd, tau) of an n-joint robot."""
    joints = {head: [f"{head}{i}" for i in range(1, n + 1)] for head in ("q", "qd", "qdd", "tau")}
    if not floating:
        return {"t": ["t"], **joints}
    base = {"q": BASE_POSITION_NAMES, "qd": BASE_VELOCITY_NAMES, "qdd": BASE_ACCELERATION_NAMES}
    base["tau"] = BASE_WRENCH_NAMES
    return {"t": ["t"], **{head: [*base[head], *names] for head, names in joints.items()}}


def _sizes(n: int, floating: bool) -> str:
    if not floating:
        return f"{n} joints"
    return f"a floating robot: NQ = {n + 7} position columns, NV = {n + 6} for qd, qdd and tau"


def _columns(header: list[str], n: int, where: str, torques: bool, floating: bool) -> dict[str, list[int]]:
    """Indices of t, q, qd, qdd (and tau when `torques`) in the header (qd and qdd may be missing)."""
    index = {name.strip(): k for k, name in enumerate(header)}
    out: dict[str, list[int]] = {}
    for head, names in log_columns(n, floating).items():
        if head == "tau" and not torques:
            continue
        if head in ("qd", "qdd") and not any(c in index for c in names):
            continue
        missing = [c for c in names if c not in index]
        if missing:
            raise SymdynError(
                f"{where}: missing column(s) {', '.join(missing)} ({_sizes(n, floating)}; the header "
                f"is {','.join(header)})"
            )
        out[head] = [index[c] for c in names]
    if floating and "qd" not in out:
        raise SymdynError(
            f"{where}: a floating robot's log needs its velocity columns "
            f"{', '.join(log_columns(n, True)['qd'])} "
            "(the quaternion is not differentiated column by column)"
        )
    if not floating and ("qd" in out) != ("qdd" in out):
        raise SymdynError(f"{where}: give both qd1..qd{n} and qdd1..qdd{n}, or neither")
    return out


def read_measurements(
    path: str | os.PathLike, n: int, torques: bool = True, floating: bool = False
) -> Measurements:
    """Measurements of an n-joint robot (floating: its free flyer's columns too) from a log file
    (see the module docstring: .csv, .npz or .npy).

    With torques=False the tau columns are not required (a reference trajectory, e.g. the file
    `symdyn excite` writes, for `symdyn simulate --track FILE.csv`); `tau` is then empty.

    Raises:
        SymdynError: no such file, a missing column, a value that is not a finite number,
            or too few samples; the message names the file (and the line and column).
    """
    where = str(path)
    suffix = Path(path).suffix.lower()
    size = _regular_file(path, where)
    if suffix in (".npz", ".npy"):
        from .measurements_binary import read_binary

        header, data = read_binary(path, log_columns(n, floating), MAX_LOG_BYTES)
        cols = _columns(header, n, where, torques, floating)
    else:
        try:
            header, data, line = _read_csv(path, where, size)
        except MemoryError:
            raise SymdynError(f"{where}: not enough memory to read it (MemoryError)") from None
        cols = _columns(header, n, f"{where}: line {line}", torques, floating)
    if len(data) < 2:
        raise SymdynError(f"{where}: too few samples ({len(data)})")
    t, q = data[:, cols["t"][0]], data[:, cols["q"]]
    tau = data[:, cols["tau"]] if torques else np.empty((len(data), 0))
    if "qdd" in cols:
        return Measurements(t, q, data[:, cols["qd"]], data[:, cols["qdd"]], tau)
    if floating:
        qd = data[:, cols["qd"]]
        return Measurements(t, q, qd, differentiate(t, qd, where, orders=(1,))[0], tau, differentiated=True)
    q, qd, qdd = differentiate(t, q, where)
    return Measurements(t, q, qd, qdd, tau, differentiated=True)


def _regular_file(path: str | os.PathLike, where: str) -> int:
    """The size of the log at `path`, a regular file (symbolic links followed); else SymdynError."""
    try:
        info = os.stat(path)
    except OSError as exc:
        raise SymdynError(f"{where}: cannot read ({exc.strerror or exc})") from None
    if stat.S_ISDIR(info.st_mode):
        raise SymdynError(f"{where}: is a folder, not a log file")
    if not stat.S_ISREG(info.st_mode):
        raise SymdynError(
            f"{where}: not a regular file (a device, FIFO or socket, which may never end): "
            "symdyn reads a log from a file"
        )
    return info.st_size


def _read_csv(path: str | os.PathLike, where: str, size: int) -> tuple[list[str], np.ndarray, int]:
    """(header, values (N, columns), the header's line number) of a CSV log of `size` bytes:
    pandas' parser, else numpy.loadtxt, else Python."""
    header, skip = None, 0
    try:
        with open(path, "rb") as f:
            for line in iter(lambda: f.readline(MAX_LINE), b""):
                skip += 1
                if len(line) == MAX_LINE and not line.endswith(b"\n"):
                    raise SymdynError(f"{where}: line {skip} is longer than {MAX_LINE} bytes: not a CSV log")
                try:
                    row = next(csv.reader([line.decode()]), [])
                except UnicodeDecodeError as exc:
                    raise SymdynError(f"{where}: not a text file ({exc.reason})") from None
                except csv.Error as exc:
                    raise SymdynError(f"{where}: line {skip}: {exc}") from None
                if row and any(c.strip() for c in row):
                    header = row
                    break
    except OSError as exc:
        raise SymdynError(f"{where}: cannot read ({exc.strerror or exc})") from None
    if header is None:
        raise SymdynError(f"{where}: empty file (expected a header t,q1..,tau1..)")
    _check_rows(path, where, len(header), size)
    data = parse_rows(path, skip, len(header))
    if data is None:
        data = _loadtxt(path, skip, len(header))
    if data is None or not np.all(np.isfinite(data)):
        data = _read_slowly(path, header, skip)
    return header, data, skip


def _check_rows(path: str | os.PathLike, where: str, width: int, size: int) -> None:
    """SymdynError when the CSV's lines of `width` values would take more than MAX_LOG_BYTES.

    A value takes at least two characters ("0,"), so a file of at most MAX_LOG_BYTES / 4 bytes
    cannot; a larger one has its lines counted first (a read at disk speed, no parsing)."""
    if size <= MAX_LOG_BYTES // 4:
        return
    lines = 1
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(2**24), b""):
            lines += block.count(b"\n")
    if 8 * width * lines > MAX_LOG_BYTES:
        from .measurements_binary import size_text

        raise SymdynError(
            f"{where}: {lines} lines of {width} values take {size_text(8 * width * lines)}, more than a "
            f"log may hold ({size_text(MAX_LOG_BYTES)}: "
            "symdyn.apps.identification.measurements.MAX_LOG_BYTES)"
        )


def _loadtxt(path: str | os.PathLike, skip: int, width: int) -> np.ndarray | None:
    """The values after the first `skip` lines by numpy.loadtxt, or None when it refuses them or
    finds another count a line."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # numpy's "input contained no data"
            data = np.loadtxt(path, delimiter=",", comments=None, dtype=np.float64, ndmin=2, skiprows=skip)
    except (ValueError, UnicodeDecodeError, OSError):
        return None
    return data if not len(data) or data.shape[1] == width else None


def _read_slowly(path: str | os.PathLike, header: list[str], skip: int) -> np.ndarray:
    """The values after the header (its line is number `skip`) by Python's csv and float; a
    SymdynError naming the line and column of the first wrong value."""
    where = str(path)
    with open(path, newline="") as f:
        try:
            return _parse_slowly(where, csv.reader(f), header, skip)
        except UnicodeDecodeError as exc:
            raise SymdynError(f"{where}: not a text file ({exc.reason})") from None


def _parse_slowly(where: str, rows, header: list[str], skip: int) -> np.ndarray:
    """The values of the csv.reader `rows` after line `skip` (see `_read_slowly`)."""
    width = len(header)
    names = [h.strip() for h in header]
    values = array("d")  # 8 bytes a value, as the array it becomes
    for k, row in _numbered(where, rows):
        if k <= skip or not row or not any(c.strip() for c in row):
            continue
        if len(row) != width:
            raise SymdynError(f"{where}: line {k} has {len(row)} values, the header {width}")
        for c, name in zip(row, names, strict=True):
            try:
                x = float(c)
            except ValueError:
                raise SymdynError(f"{where}: line {k}: not a number in column {name}: '{c}'") from None
            if not np.isfinite(x):
                raise SymdynError(f"{where}: line {k}: column {name} is {c.strip()}, not a finite number")
            values.append(x)
    return np.frombuffer(values, dtype=np.float64).reshape(-1, width).copy()


def _numbered(where: str, rows):
    """(line number, row) of a csv.reader; a row it refuses (a field past csv's size limit) is a
    SymdynError naming its line."""
    k = 0
    while True:
        k += 1
        try:
            row = next(rows)
        except StopIteration:
            return
        except csv.Error as exc:
            raise SymdynError(f"{where}: line {k}: {exc}") from None
        yield k, row


def needs_scipy(module: str):
    """scipy.<module>, or a SymdynError saying how to install it (the `ident` extra)."""
    import importlib

    try:
        return importlib.import_module(f"scipy.{module}")
    except ImportError:
        raise SymdynError("identification needs scipy (pip install 'symdyn[ident]')") from None


def differentiate(
    t: np.ndarray,
    q: np.ndarray,
    where: str = "differentiate",
    window: int = SG_WINDOW,
    orders: tuple[int, ...] = (0, 1, 2),
):
    """The Savitzky-Golay filter's derivatives of q of each order in `orders` (default: q, qd,
    qdd; module docstring); t evenly spaced."""
    savgol_filter = needs_scipy("signal").savgol_filter
    dt = np.diff(t)
    if len(t) < window:
        raise SymdynError(f"{where}: {len(t)} samples, the Savitzky-Golay filter needs at least {window}")
    if not (np.all(dt > 0) and np.ptp(dt) <= 1e-6 * np.mean(dt)):
        raise SymdynError(f"{where}: without qd and qdd columns the times t must be evenly spaced")
    h = float(np.mean(dt))
    with np.errstate(all="ignore"):
        try:
            out = tuple(savgol_filter(q, window, SG_ORDER, deriv=d, delta=h, axis=0) for d in orders)
        except (ZeroDivisionError, OverflowError):  # delta ** 2 underflows to 0 for tiny steps
            out = (np.array(np.inf),)
    if not all(np.isfinite(x).all() for x in out):
        raise SymdynError(
            f"{where}: the Savitzky-Golay derivatives overflow (samples {h:g} s apart): give qd and qdd "
            "columns, or times in seconds"
        )
    return out
