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

The CSV's numbers are parsed by pandas' C parser when pandas is installed (symdyn.apps.csv_read;
the `ident` extra installs it), else by numpy.loadtxt; a file both refuse is read again line by
line (Python's csv and float) for a message naming the line and column, or for its values when
Python reads what they do not (1_000). Missing velocities and accelerations of a fixed-base log are estimated
from q by a Savitzky-Golay filter (scipy.signal.savgol_filter; Savitzky and Golay, 1964): a
polynomial of degree SG_ORDER fitted by least squares to each window of SG_WINDOW samples (odd),
whose value and first two derivatives at the window's centre replace q, qd and qdd; a floating
log without accelerations gets qdd as the filter's derivative of qd (v lives in a vector space,
the base's part in the base frame; q and qd stay as measured). The samples must then be evenly
spaced in t.
"""

from __future__ import annotations

import csv
import io
import os
import warnings
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
]

#: Savitzky-Golay window (samples, odd) and polynomial degree for qd and qdd from q
SG_WINDOW = 21
SG_ORDER = 4


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
    if suffix in (".npz", ".npy"):
        from .measurements_binary import read_binary

        header, data = read_binary(path, log_columns(n, floating))
        cols = _columns(header, n, where, torques, floating)
    else:
        header, data, line = _read_csv(path, where)
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


def _read_csv(path: str | os.PathLike, where: str) -> tuple[list[str], np.ndarray, int]:
    """(header, values (N, columns), the header's line number) of a CSV log: pandas' parser, else
    numpy.loadtxt, else Python."""
    header, skip = None, 0
    try:
        with open(path, "rb") as f:
            for line in f:
                skip += 1
                try:
                    row = next(csv.reader([line.decode()]), [])
                except UnicodeDecodeError as exc:
                    raise SymdynError(f"{where}: not a text file ({exc.reason})") from None
                if row and any(c.strip() for c in row):
                    header = row
                    break
    except OSError as exc:
        raise SymdynError(f"{where}: cannot read ({exc.strerror or exc})") from None
    if header is None:
        raise SymdynError(f"{where}: empty file (expected a header t,q1..,tau1..)")
    data = parse_rows(path, skip, len(header))
    if data is None:
        data = _loadtxt(path, skip, len(header))
    if data is None or not np.all(np.isfinite(data)):
        data = _read_slowly(path, header, skip)
    return header, data, skip


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
    where, width = str(path), len(header)
    names = [h.strip() for h in header]
    try:
        text = Path(path).read_text()
    except UnicodeDecodeError as exc:
        raise SymdynError(f"{where}: not a text file ({exc.reason})") from None
    values = []
    for k, row in enumerate(csv.reader(io.StringIO(text)), start=1):
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
    return np.array(values, dtype=np.float64).reshape(-1, width)


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
    return tuple(savgol_filter(q, window, SG_ORDER, deriv=d, delta=h, axis=0) for d in orders)
