"""Identification of the base parameters from measured joint torques (weighted least squares).

tau = Y_b(q, qd, qdd) pi_b (symdyn.algorithms.base_parameters), so N samples stacked give the
overdetermined linear system  y = W pi_b  with W (N n x nbase) the base regressor at every sample
and y the measured torques. W is never held whole: it is evaluated a chunk of samples at a time
(the compiled C base_regressor's batch call, about CHUNK_BYTES a chunk) and each joint's rows
[W_j | y_j] are folded into a triangular factor by incremental QR
(symdyn.apps.identification.least_squares), from
which every least squares below, its residuals and the condition number follow exactly as from
the whole W (to rounding); memory is one chunk whatever N. Following Gautier ("Dynamic
identification of robots with power model", 1997):

1. ordinary least squares, pi_0 = argmin |y - W pi|, and per joint j the residual variance
   sigma_j^2 = |r_j|^2 / (N - nbase / n)  (the N n - nbase residual degrees of freedom shared
   equally by the n joints; a floor of 1e-12 times the joint's torque RMS, at least 1e-6 of the
   largest joint's, keeps noise-free data finite);
2. weighted least squares with every row of joint j divided by sigma_j:
   pi_b = argmin |G (y - W pi)|, covariance C = s^2 (W^T G^2 W)^-1 with
   s^2 = |G (y - W pi_b)|^2 / (N n - nbase); the standard deviation of estimate k is sqrt(C_kk)
   and its relative standard deviation 100 sqrt(C_kk) / |pi_b,k| percent.

The condition number is that of the stacked base regressor W (2-norm: largest over smallest
singular value); the residual RMS is per joint, with the final estimates. Warnings: a condition
number above HIGH_CONDITION, or a relative standard deviation above HIGH_RELATIVE_STD percent.

Measurements: symdyn.apps.identification.measurements (CSV, .npz or .npy logs). A floating robot (NV = 6 + n
rows per sample, symdyn.model.free_flyer) is identified the same way with its floating regressor:
the six base rows (the wrench on the base in the base frame, zero in free flight) are rows like
the joints' (each with its own sigma), so a log of a robot in flight also constrains the
parameters through its zero base wrench; "joint" above then means "row of NV".
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ...errors import SymdynError
from ...model.parameter_names import MAX_MAGNITUDE
from ...model.robot import Robot
from .least_squares import Triangular, combine, one_blas_thread
from .measurements import SG_ORDER, SG_WINDOW, Measurements, differentiate, needs_scipy, read_measurements

# the log reading lives in symdyn.apps.identification.measurements; its names stay importable here
__all__ = [
    "Measurements",
    "read_measurements",
    "differentiate",
    "needs_scipy",
    "SG_WINDOW",
    "SG_ORDER",
    "Identification",
    "base_regressor_samples",
    "identify",
    "HIGH_CONDITION",
    "HIGH_RELATIVE_STD",
    "CHUNK_BYTES",
    "chunk_samples",
]

#: condition numbers of the stacked base regressor above this are reported as high
HIGH_CONDITION = 1000.0
#: relative standard deviations (percent) above this are reported
HIGH_RELATIVE_STD = 10.0
#: bytes of base regressor `identify` evaluates per batch call (the chunk it holds at a time)
CHUNK_BYTES = 16 * 2**20


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


def _regressor(robot: Robot):
    """A function (q, qd, qdd) of N samples -> Y_b, (N, n, nbase): the compiled C base_regressor's
    batch call (symdyn.compile, cached; its loop over the samples is in C, W samples per
    instruction), or the generated NumPy module without a C compiler; the robot's parameters
    must all have values."""
    if robot.floating:  # the regressor group is not among a floating robot's default groups
        from ..compilation.compile import compile

        f = compile(robot, functions=("regressor",)).base_regressor
    else:
        from ..compilation.compiled import compiled_dynamics

        f = compiled_dynamics(robot).base_regressor

    def evaluate(q, qd, qdd) -> np.ndarray:
        Yb = f(*(np.asarray(a, dtype=float) for a in (q, qd, qdd)))
        return np.asarray(Yb, dtype=float).reshape(len(q), robot.nv, -1)

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
    folded into one triangular factor per joint (symdyn.apps.identification.least_squares), so the memory is
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
        SymdynError: fewer equations than base parameters; measurements of another size.
    """
    N, n = data.tau.shape
    nb = len(base)
    if n != robot.nv or data.q.shape[1] != robot.nq:
        raise SymdynError(
            f"identify: robot '{robot.name}' has NQ = {robot.nq} positions and NV = {robot.nv} torques, "
            f"the measurements {data.q.shape[1]} and {n}"
        )
    if N * n <= nb:
        raise SymdynError(
            f"{N} samples of {n} rows give {N * n} equations for {nb} base parameters: need more"
        )
    regressor = _regressor(robot)
    step = chunk_samples(n, nb) if chunk is None else max(1, int(chunk))
    chunks = [slice(s, min(s + step, N)) for s in range(0, N, step)]
    joints = [Triangular(nb) for _ in range(n)]  # [W_j | y_j]: the rows of joint j
    _check_bounded(data.tau, data.t, "the torque tau{}")
    with one_blas_thread():
        for s in chunks:
            W3 = regressor(data.q[s], data.qd[s], data.qdd[s])
            assert W3.shape[2] == nb, (W3.shape, nb)
            _check_bounded(W3, data.t[s], "the base regressor's row {}", s.start)
            for j, part in enumerate(joints):
                part.add(W3[:, j, :], data.tau[s, j])
    plain = combine(joints, np.ones(n))
    x0 = plain.solve()
    r2 = np.array([part.residual_norm(x0) ** 2 for part in joints])
    rms = np.sqrt(np.mean(data.tau**2, axis=0))  # a row of zeros (free flight's base wrench): the others'
    floor = 1e-12 * np.maximum(rms, max(1e-6 * rms.max(), 1e-300))
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


def _check_bounded(values: np.ndarray, t: np.ndarray, what: str, start: int = 0) -> None:
    """SymdynError unless every entry of `values` (samples first; the second axis the row of a
    sample) is at most MAX_MAGNITUDE in absolute value (so that the QR's products stay finite):
    names the first sample, its time and the row (`what` formatted with it, 1-based)."""
    if not values.size or (values.min() >= -MAX_MAGNITUDE and values.max() <= MAX_MAGNITUDE):
        return
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(values) <= MAX_MAGNITUDE)  # NaN too
    k, j = np.argwhere(bad)[0][:2]
    x = np.asarray(values[k, j]).flat[np.flatnonzero(bad[k, j])[0]]
    why = f"more than {MAX_MAGNITUDE:g} in absolute value" if np.isfinite(x) else "not finite"
    raise SymdynError(
        f"identify: {what.format(j + 1)} at sample {start + k} (t = {t[k]:g} s) is {x:g}, {why} (the "
        "least squares would overflow): give the log in SI units"
    )


def plot_identification(
    result: Identification, data: Measurements, path: str | os.PathLike | None = None
) -> bytes:
    """Measured and predicted (Y_b pi_b) torque per joint against time; the image bytes, also
    written atomically to `path` when given (png, pdf or svg by its suffix)."""
    from ..output import figure, figure_bytes, plot_format, write_atomic

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
