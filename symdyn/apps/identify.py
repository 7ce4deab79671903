"""Identification of the base parameters from measured joint torques (weighted least squares).

tau = Y_b(q, qd, qdd) pi_b (symdyn.algorithms.base_parameters), so N samples stacked give the
overdetermined linear system  y = W pi_b  with W (N n x nbase) the base regressor at every sample
and y the measured torques. W is never held whole: it is evaluated a chunk of samples at a time
(the compiled C base_regressor's batch call, about CHUNK_BYTES a chunk) and each joint's rows
[W_j | y_j] are folded into a triangular factor by incremental QR (symdyn.apps.least_squares), from
which every least squares below, its residuals and the condition number follow exactly as from
the whole W (to rounding); memory is one chunk whatever N. Following Gautier ("Dynamic
identification of robots with power model", 1997):

1. ordinary least squares, pi_0 = argmin |y - W pi|, and per joint j the residual variance
   sigma_j^2 = |r_j|^2 / (N - nbase / n)  (the N n - nbase residual degrees of freedom shared
   equally by the n joints; a floor of 1e-12 times the joint's torque RMS keeps noise-free data
   finite);
2. weighted least squares with every row of joint j divided by sigma_j:
   pi_b = argmin |G (y - W pi)|, covariance C = s^2 (W^T G^2 W)^-1 with
   s^2 = |G (y - W pi_b)|^2 / (N n - nbase); the standard deviation of estimate k is sqrt(C_kk)
   and its relative standard deviation 100 sqrt(C_kk) / |pi_b,k| percent.

The condition number is that of the stacked base regressor W (2-norm: largest over smallest
singular value); the residual RMS is per joint, with the final estimates. Warnings: a condition
number above HIGH_CONDITION, or a relative standard deviation above HIGH_RELATIVE_STD percent.

Measurements (`read_measurements`): a CSV file with a header naming the columns t, q1..qn,
optionally qd1..qdn and qdd1..qddn, and tau1..taun. Without velocities and accelerations they are
estimated from q by a Savitzky-Golay filter (scipy.signal.savgol_filter; Savitzky and Golay, 1964):
a polynomial of degree SG_ORDER fitted by least squares to each window of SG_WINDOW samples
(odd), whose value and first two derivatives at the window's centre replace q, qd and qdd; the
samples must then be evenly spaced in t.
"""

from __future__ import annotations

import csv
import io
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SymdynError
from ..model.robot import Robot
from .least_squares import Triangular, combine

__all__ = [
    "Measurements",
    "Identification",
    "read_measurements",
    "differentiate",
    "needs_scipy",
    "base_regressor_samples",
    "identify",
    "HIGH_CONDITION",
    "HIGH_RELATIVE_STD",
    "SG_WINDOW",
    "SG_ORDER",
    "CHUNK_BYTES",
    "chunk_samples",
]

#: condition numbers of the stacked base regressor above this are reported as high
HIGH_CONDITION = 1000.0
#: relative standard deviations (percent) above this are reported
HIGH_RELATIVE_STD = 10.0
#: Savitzky-Golay window (samples, odd) and polynomial degree for qd and qdd from q
SG_WINDOW = 21
SG_ORDER = 4
#: bytes of base regressor `identify` evaluates per batch call (the chunk it holds at a time)
CHUNK_BYTES = 16 * 2**20


@dataclass
class Measurements:
    """N samples: times t (N,), joint positions q, velocities qd, accelerations qdd, torques tau (N, n)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    differentiated: bool = False  # qd and qdd were estimated from q (Savitzky-Golay)


@dataclass
class Identification:
    """The estimates of the base parameters, in the order of base_regressor's columns."""

    names: tuple[str, ...]
    expressions: tuple[str, ...]
    estimate: np.ndarray
    std: np.ndarray
    condition_number: float
    residual_rms: np.ndarray
    samples: int
    predicted: np.ndarray | None  # (N, n): Y_b pi_b at every sample (None: not computed)

    @property
    def relative_std(self) -> np.ndarray:
        """100 std / |estimate| (percent; inf for an estimate of 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.estimate != 0, 100.0 * self.std / np.abs(self.estimate), np.inf)

    def warnings(self) -> list[str]:
        """One line per problem: a high condition number, poorly determined parameters."""
        out = []
        if not self.condition_number <= HIGH_CONDITION:
            out.append(
                f"the stacked base regressor is poorly conditioned (condition number "
                f"{self.condition_number:.3g} > {HIGH_CONDITION:g}): excite the robot more (symdyn excite)"
            )
        bad = [
            f"{n} ({r:.3g} %)"
            for n, r in zip(self.names, self.relative_std, strict=True)
            if r > HIGH_RELATIVE_STD
        ]
        if bad:
            out.append(f"relative standard deviation above {HIGH_RELATIVE_STD:g} %: {', '.join(bad)}")
        return out

    def as_dict(self) -> dict:
        """The JSON report: base_parameters (name, expression, estimate, std), condition_number,
        residual_rms (per joint), samples."""
        return {
            "base_parameters": [
                {"name": n, "expression": e, "estimate": float(x), "std": float(s)}
                for n, e, x, s in zip(self.names, self.expressions, self.estimate, self.std, strict=True)
            ],
            "condition_number": float(self.condition_number),
            "residual_rms": [float(x) for x in self.residual_rms],
            "samples": int(self.samples),
        }

    def text(self) -> str:
        """A table of the estimates, then the condition number and residual RMS per joint."""
        width = max(len(n) for n in self.names)
        lines = [f"{'parameter'.ljust(width)}  {'estimate':>14}  {'std':>11}  {'rel. std':>9}  definition"]
        for n, e, x, s, r in zip(
            self.names, self.expressions, self.estimate, self.std, self.relative_std, strict=True
        ):
            lines.append(f"{n.ljust(width)}  {x:14.6g}  {s:11.3g}  {r:8.3g}%  {e}")
        lines.append(f"samples: {self.samples}")
        lines.append(f"condition number of the stacked base regressor: {self.condition_number:.4g}")
        rms = ", ".join(f"{x:.4g}" for x in self.residual_rms)
        lines.append(f"residual RMS per joint (N m or N): {rms}")
        return "\n".join(lines) + "\n"


def _columns(header: list[str], n: int, where: str, torques: bool = True) -> dict[str, list[int]]:
    """Indices of t, q, qd, qdd (and tau when `torques`) in the header (qd and qdd may be missing)."""
    index = {name.strip(): k for k, name in enumerate(header)}
    out: dict[str, list[int]] = {}
    for head in ("t", "q", "qd", "qdd", "tau") if torques else ("t", "q", "qd", "qdd"):
        names = ["t"] if head == "t" else [f"{head}{i}" for i in range(1, n + 1)]
        present = [c for c in names if c in index]
        if head in ("qd", "qdd") and not present:
            continue
        missing = [c for c in names if c not in index]
        if missing:
            raise SymdynError(
                f"{where}: missing column(s) {', '.join(missing)} (the header is {','.join(header)})"
            )
        out[head] = [index[c] for c in names]
    if ("qd" in out) != ("qdd" in out):
        raise SymdynError(f"{where}: give both qd1..qd{n} and qdd1..qdd{n}, or neither")
    return out


def read_measurements(path: str | os.PathLike, n: int, torques: bool = True) -> Measurements:
    """Measurements of an n-joint robot from a CSV file (see the module docstring).

    With torques=False the tau columns are not required (a reference trajectory, e.g. the file
    `symdyn excite` writes, for `symdyn simulate --track FILE.csv`); `tau` is then empty.
    The values are parsed by numpy.loadtxt (C, about 1 s a million lines of 29 values); a file it
    refuses is read again line by line (Python's csv and float) for the message, or the values
    when Python accepts what NumPy does not (a quoted number, 1_000).

    Raises:
        SymdynError: no such file, a missing column, a value that is not a finite number,
            or too few samples; the message names the file (and the line and column).
    """
    where = str(path)
    try:
        with open(path, newline="") as f:
            header, skip = None, 0
            for line in f:
                skip += 1
                row = next(csv.reader([line]), [])
                if row and any(c.strip() for c in row):
                    header = row
                    break
            if header is None:
                raise SymdynError(f"{where}: empty file (expected a header t,q1..,tau1..)")
            cols = _columns(header, n, where, torques)
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")  # numpy's "input contained no data"
                    data = np.loadtxt(f, delimiter=",", comments=None, dtype=np.float64, ndmin=2)
            except ValueError:
                data = None
    except OSError as exc:
        raise SymdynError(f"{where}: cannot read ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise SymdynError(f"{where}: not a text file ({exc.reason})") from None
    if data is None or (len(data) and data.shape[1] != len(header)) or not np.all(np.isfinite(data)):
        data = _read_slowly(path, header, skip)
    if len(data) < 2:
        raise SymdynError(f"{where}: too few samples ({len(data)})")
    t, q = data[:, cols["t"][0]], data[:, cols["q"]]
    tau = data[:, cols["tau"]] if torques else np.empty((len(data), 0))
    if "qd" in cols:
        return Measurements(t, q, data[:, cols["qd"]], data[:, cols["qdd"]], tau)
    q, qd, qdd = differentiate(t, q, where)
    return Measurements(t, q, qd, qdd, tau, differentiated=True)


def _read_slowly(path: str | os.PathLike, header: list[str], skip: int) -> np.ndarray:
    """The values after the header (its line is number `skip`) by Python's csv and float; a
    SymdynError naming the line and column of the first wrong value."""
    where, width = str(path), len(header)
    names = [h.strip() for h in header]
    text = Path(path).read_text()
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


def differentiate(t: np.ndarray, q: np.ndarray, where: str = "differentiate", window: int = SG_WINDOW):
    """(q, qd, qdd) by a Savitzky-Golay filter of q (module docstring); t evenly spaced."""
    savgol_filter = needs_scipy("signal").savgol_filter
    dt = np.diff(t)
    if len(t) < window:
        raise SymdynError(f"{where}: {len(t)} samples, the Savitzky-Golay filter needs at least {window}")
    if not (np.all(dt > 0) and np.ptp(dt) <= 1e-6 * np.mean(dt)):
        raise SymdynError(f"{where}: without qd and qdd columns the times t must be evenly spaced")
    h = float(np.mean(dt))
    return tuple(savgol_filter(q, window, SG_ORDER, deriv=d, delta=h, axis=0) for d in (0, 1, 2))


def _regressor(robot: Robot):
    """A function (q, qd, qdd) of N samples -> Y_b, (N, n, nbase): the compiled C base_regressor's
    batch call (symdyn.compile, cached; its loop over the samples is in C, W samples per
    instruction), or the generated NumPy module without a C compiler; the robot's parameters
    must all have values."""
    from .compiled import compiled_dynamics

    f = compiled_dynamics(robot).base_regressor

    def evaluate(q, qd, qdd) -> np.ndarray:
        Yb = f(*(np.asarray(a, dtype=float) for a in (q, qd, qdd)))
        return np.asarray(Yb, dtype=float).reshape(len(q), robot.n, -1)

    return evaluate


def base_regressor_samples(robot: Robot, q, qd, qdd) -> np.ndarray:
    """Y_b at N samples, (N, n, nbase), in one batch call (see `_regressor`)."""
    return _regressor(robot)(q, qd, qdd)


def chunk_samples(n: int, nbase: int) -> int:
    """Samples per chunk of `identify`: a regressor chunk of about CHUNK_BYTES."""
    return max(1, CHUNK_BYTES // (8 * n * nbase))


def identify(
    robot: Robot,
    data: Measurements,
    base: tuple[tuple[str, object], ...],
    chunk: int | None = None,
    predict: bool = True,
) -> Identification:
    """Weighted least-squares estimates of the base parameters (module docstring).

    The base regressor is evaluated `chunk` samples at a time (default `chunk_samples`) and
    folded into one triangular factor per joint (symdyn.apps.least_squares), so the memory is
    one chunk whatever the number of samples; the estimates, standard deviations, residuals
    and condition number are those of the least squares on the whole stacked regressor.

    Args:
        robot: the model (every parameter with a value); its inertial values are not used.
        data: the measurements (N samples).
        base: (name, expression) per base parameter, in the order of base_regressor's columns
            (`Dynamics.base_parameters`).
        chunk: samples per batch call of the base regressor.
        predict: compute `predicted` (Y_b pi_b at every sample: a second pass over the chunks);
            without it `predicted` is None.

    Raises:
        SymdynError: fewer equations than base parameters; a floating robot.
    """
    if robot.floating:
        raise SymdynError(
            f"identify: robot '{robot.name}' has a floating base, which identification does not handle "
            "yet (its regressor is generated: docs/floating-base.md)"
        )
    N, n = data.tau.shape
    nb = len(base)
    if N * n <= nb:
        raise SymdynError(
            f"{N} samples of {n} joints give {N * n} equations for {nb} base parameters: need more"
        )
    regressor = _regressor(robot)
    step = chunk_samples(n, nb) if chunk is None else max(1, int(chunk))
    chunks = [slice(s, min(s + step, N)) for s in range(0, N, step)]
    joints = [Triangular(nb) for _ in range(n)]  # [W_j | y_j]: the rows of joint j
    for s in chunks:
        W3 = regressor(data.q[s], data.qd[s], data.qdd[s])
        assert W3.shape[2] == nb, (W3.shape, nb)
        for j, part in enumerate(joints):
            part.add(W3[:, j, :], data.tau[s, j])
    plain = combine(joints, np.ones(n))
    x0 = plain.solve()
    r2 = np.array([part.residual_norm(x0) ** 2 for part in joints])
    floor = 1e-12 * np.maximum(np.sqrt(np.mean(data.tau**2, axis=0)), 1e-300)
    sigma = np.maximum(np.sqrt(r2 / max(N - nb / n, 1.0)), floor)
    weighted = combine(joints, 1.0 / sigma)
    x = weighted.solve()
    s2 = weighted.residual_norm(x) ** 2 / (N * n - nb)
    cov = s2 * weighted.covariance_factor()
    predicted = None
    if predict:
        predicted = np.empty((N, n))
        for s in chunks:
            predicted[s] = regressor(data.q[s], data.qd[s], data.qdd[s]) @ x
    return Identification(
        names=tuple(name for name, _ in base),
        expressions=tuple(str(e) for _, e in base),
        estimate=x,
        std=np.sqrt(np.maximum(np.diag(cov), 0.0)),
        condition_number=plain.condition_number(),
        residual_rms=np.array([part.residual_norm(x) for part in joints]) / np.sqrt(N),
        samples=N,
        predicted=predicted,
    )


def plot_identification(
    result: Identification, data: Measurements, path: str | os.PathLike | None = None
) -> bytes:
    """Measured and predicted (Y_b pi_b) torque per joint against time; the image bytes, also
    written atomically to `path` when given (png, pdf or svg by its suffix)."""
    from .output import figure, figure_bytes, plot_format, write_atomic

    fmt = plot_format(path) if path is not None else "png"
    n = data.tau.shape[1]
    fig = figure(n, height_per_row=1.8)
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    for j, ax in enumerate(axes):
        ax.plot(data.t, data.tau[:, j], color="C0", lw=1.0, label=f"tau{j + 1} measured")
        ax.plot(data.t, result.predicted[:, j], "--", color="C1", lw=1.0, label="predicted Y_b pi_b")
        ax.set_ylabel(f"tau{j + 1}")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize="small", ncol=2)
    axes[0].set_title(
        f"identification: {result.samples} samples, condition number {result.condition_number:.3g}"
    )
    axes[-1].set_xlabel("t (s)")
    image = figure_bytes(fig, fmt)
    if path is not None:
        write_atomic(path, image)
    return image
