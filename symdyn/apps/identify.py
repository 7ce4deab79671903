"""Identification of the base parameters from measured joint torques (weighted least squares).

tau = Y_b(q, qd, qdd) pi_b (symdyn.algorithms.base_parameters), so N samples stacked give the
overdetermined linear system  y = W pi_b  with W (N n x nbase) the base regressor at every sample
(evaluated by the compiled C base_regressor in one batch, `base_regressor_samples`) and y the
measured torques. Following Gautier ("Dynamic identification of robots with power model", 1997):

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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SymdynError
from ..model.robot import Robot

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
]

#: condition numbers of the stacked base regressor above this are reported as high
HIGH_CONDITION = 1000.0
#: relative standard deviations (percent) above this are reported
HIGH_RELATIVE_STD = 10.0
#: Savitzky-Golay window (samples, odd) and polynomial degree for qd and qdd from q
SG_WINDOW = 21
SG_ORDER = 4


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
    predicted: np.ndarray  # (N, n): Y_b pi_b at every sample

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

    Raises:
        SymdynError: no such file, a missing column, a value that is not a finite number,
            or too few samples; the message names the file (and the line).
    """
    where = str(path)
    try:
        text = Path(path).read_text()
    except OSError as exc:
        raise SymdynError(f"{where}: cannot read ({exc.strerror or exc})") from None
    rows = [r for r in csv.reader(io.StringIO(text)) if r and any(c.strip() for c in r)]
    if not rows:
        raise SymdynError(f"{where}: empty file (expected a header t,q1..,tau1..)")
    cols = _columns(rows[0], n, where, torques)
    data = np.empty((len(rows) - 1, len(rows[0])))
    for k, row in enumerate(rows[1:], start=2):
        if len(row) != len(rows[0]):
            raise SymdynError(f"{where}: line {k} has {len(row)} values, the header {len(rows[0])}")
        try:
            data[k - 2] = [float(c) for c in row]
        except ValueError:
            raise SymdynError(f"{where}: line {k}: not a number in '{','.join(row)}'") from None
    if not np.all(np.isfinite(data)):
        raise SymdynError(f"{where}: values must be finite numbers")
    if len(data) < 2:
        raise SymdynError(f"{where}: too few samples ({len(data)})")
    t, q = data[:, cols["t"][0]], data[:, cols["q"]]
    tau = data[:, cols["tau"]] if torques else np.empty((len(data), 0))
    if "qd" in cols:
        return Measurements(t, q, data[:, cols["qd"]], data[:, cols["qdd"]], tau)
    q, qd, qdd = differentiate(t, q, where)
    return Measurements(t, q, qd, qdd, tau, differentiated=True)


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


def base_regressor_samples(robot: Robot, q, qd, qdd) -> np.ndarray:
    """Y_b at N samples, (N, n, nbase): one batch call of the compiled C base_regressor
    (symdyn.compile, cached; its loop over the samples is in C, or the generated NumPy module
    without a C compiler); the robot's parameters must all have values."""
    from .compiled import compiled_dynamics

    cd = compiled_dynamics(robot)
    Yb = cd.base_regressor(
        np.asarray(q, dtype=float), np.asarray(qd, dtype=float), np.asarray(qdd, dtype=float)
    )
    return np.asarray(Yb, dtype=float).reshape(len(q), robot.n, -1)


def identify(robot: Robot, data: Measurements, base: tuple[tuple[str, object], ...]) -> Identification:
    """Weighted least-squares estimates of the base parameters (module docstring).

    Args:
        robot: the model (every parameter with a value); its inertial values are not used.
        data: the measurements (N samples).
        base: (name, expression) per base parameter, in the order of base_regressor's columns
            (`Dynamics.base_parameters`).

    Raises:
        SymdynError: fewer equations than base parameters; a floating robot.
    """
    if robot.floating:
        raise SymdynError(
            f"identify: robot '{robot.name}' has a floating base, which identification does not handle "
            "yet (its regressor is generated: docs/floating-base.md)"
        )
    W3 = base_regressor_samples(robot, data.q, data.qd, data.qdd)
    N, n, nb = W3.shape
    assert nb == len(base), (nb, len(base))
    if N * n <= nb:
        raise SymdynError(
            f"{N} samples of {n} joints give {N * n} equations for {nb} base parameters: need more"
        )
    W = W3.reshape(N * n, nb)
    y = data.tau.reshape(N * n)
    x0 = np.linalg.lstsq(W, y, rcond=None)[0]
    r = (y - W @ x0).reshape(N, n)
    floor = 1e-12 * np.maximum(np.sqrt(np.mean(data.tau**2, axis=0)), 1e-300)
    sigma = np.maximum(np.sqrt(np.sum(r**2, axis=0) / max(N - nb / n, 1.0)), floor)
    g = np.tile(1.0 / sigma, N)
    x = np.linalg.lstsq(W * g[:, None], y * g, rcond=None)[0]
    res = y - W @ x
    s2 = np.sum((g * res) ** 2) / (N * n - nb)
    cov = s2 * np.linalg.pinv((W * g[:, None]).T @ (W * g[:, None]))
    return Identification(
        names=tuple(name for name, _ in base),
        expressions=tuple(str(e) for _, e in base),
        estimate=x,
        std=np.sqrt(np.maximum(np.diag(cov), 0.0)),
        condition_number=float(np.linalg.cond(W)),
        residual_rms=np.sqrt(np.mean(res.reshape(N, n) ** 2, axis=0)),
        samples=N,
        predicted=(W @ x).reshape(N, n),
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
