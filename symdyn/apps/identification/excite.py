"""Exciting trajectories for identification: finite Fourier series optimised for the base regressor.

Every joint follows a periodic finite Fourier series with fundamental frequency w_f = 2 pi / T
and L harmonics (Swevers, Ganseman, Tukel, De Schutter and Van Brussel, "Optimal robot
excitation and identification", IEEE Trans. Robotics and Automation 13(5), 1997):

    q_i(t)   = q0_i + sum_l  a_il / (w_f l) sin(w_f l t) - b_il / (w_f l) cos(w_f l t)
    qd_i(t)  = sum_l  a_il cos(w_f l t) + b_il sin(w_f l t)
    qdd_i(t) = sum_l -a_il w_f l sin(w_f l t) + b_il w_f l cos(w_f l t)

The coefficients a, b (n x L) are chosen to minimise the condition number of the base regressor
stacked at `samples` times over one period (symdyn.apps.identification.identify evaluates it with the compiled
C base_regressor, one batch call per trial), with scipy.optimize.minimize (Powell's method, from
the best of a few random starts), stopped after `evaluations` evaluations of the condition
number (the best one is kept).
The limits |q_i - q0_i| <= q_range_i, |qd_i| <= qd_max_i, |qdd_i| <= qdd_max_i hold on the
sampled period because every trial is scaled into them: q - q0, qd and qdd are all linear in
(a, b), so the factor that brings the tightest of them to its limit is exact; the optimiser works
on the direction of (a, b) only.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import SymdynError
from ...model.robot import Robot
from ..output import write_atomic
from .identify import base_regressor_samples
from .measurements import needs_scipy

__all__ = [
    "FourierTrajectory",
    "excite",
    "csv_samples",
    "DEFAULTS",
    "MAX_SAMPLES",
    "MAX_HARMONICS",
    "PERIOD_RANGE",
    "MAX_ROWS",
]

#: the most samples per period for the condition number: each evaluation holds their base
#: regressor (samples x n x nbase doubles: 35 MB for the Panda at the limit)
MAX_SAMPLES = 10_000
#: the most harmonics per joint (Powell's method keeps a square matrix of 2 n L directions)
MAX_HARMONICS = 100
#: the periods (s) `excite` accepts: beyond them the Fourier series' amplitudes (a / (w l) and
#: a w l) leave what a robot's limits and double precision can express together
PERIOD_RANGE = (1e-6, 1e6)
#: the most samples of the CSV `write_csv` writes (period / dt + 1): about 600 MB of text for the Panda
MAX_ROWS = 1_000_000

#: period T (s), harmonics L, samples per period for the condition number, optimiser evaluations,
#: random starts, and the limits (revolute rad, rad/s, rad/s^2; prismatic m, m/s, m/s^2)
DEFAULTS = {
    "period": 10.0,
    "harmonics": 5,
    "samples": 100,
    "evaluations": 1000,
    "starts": 4,
    "q_range": {"revolute": 1.0, "prismatic": 0.1},
    "qd_max": {"revolute": 1.5, "prismatic": 0.3},
    "qdd_max": {"revolute": 3.0, "prismatic": 1.0},
}


@dataclass
class FourierTrajectory:
    """q(t) = q0 + sum_l a_l/(w l) sin(w l t) - b_l/(w l) cos(w l t) per joint (module docstring)."""

    q0: np.ndarray  # (n,)
    a: np.ndarray  # (n, L)
    b: np.ndarray  # (n, L)
    period: float
    condition_number: float = float("nan")

    @property
    def omega(self) -> float:
        return 2.0 * np.pi / self.period

    def __call__(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """q, qd, qdd at the times t (N,): three (N, n) arrays."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        wl = self.omega * np.arange(1, self.a.shape[1] + 1)  # (L,)
        s, c = np.sin(np.outer(t, wl)), np.cos(np.outer(t, wl))  # (N, L)
        q = self.q0 + s @ (self.a / wl).T - c @ (self.b / wl).T
        qd = c @ self.a.T + s @ self.b.T
        qdd = -s @ (self.a * wl).T + c @ (self.b * wl).T
        return q, qd, qdd

    def expressions(self) -> list[str]:
        """q_i(t) as text for `symdyn simulate --track` (no spaces, numbers to 12 digits)."""
        w = self.omega
        out = []
        for i in range(len(self.q0)):
            terms = [f"{self.q0[i]:.12g}"]
            for l in range(1, self.a.shape[1] + 1):
                sa, sb = self.a[i, l - 1] / (w * l), -self.b[i, l - 1] / (w * l)
                terms += [f"{sa:+.12g}*sin({w * l:.12g}*t)", f"{sb:+.12g}*cos({w * l:.12g}*t)"]
            out.append("".join(terms))
        return out

    def csv_text(self, robot: Robot, dt: float) -> str:
        """t, q, qd, qdd and tau (the robot file's inverse dynamics) over one period every dt:
        the columns `symdyn identify` reads (at most MAX_ROWS samples: `csv_samples`)."""
        from ..compilation.compiled import compiled_dynamics

        csv_samples(self.period, dt)
        t = np.arange(0.0, self.period + 0.5 * dt, dt)
        q, qd, qdd = self(t)
        tau = compiled_dynamics(robot).inverse_dynamics(q, qd, qdd)
        n = robot.n
        header = ["t"] + [f"{h}{i}" for h in ("q", "qd", "qdd", "tau") for i in range(1, n + 1)]
        rows = np.column_stack([t, q, qd, qdd, tau])
        return ",".join(header) + "\n" + "".join(",".join(f"{x:.17g}" for x in r) + "\n" for r in rows)

    def write_csv(self, robot: Robot, path: str | os.PathLike, dt: float) -> Path:
        return write_atomic(path, self.csv_text(robot, dt))


def csv_samples(period: float, dt: float) -> int:
    """The samples of one period every dt (the CSV's rows); SymdynError unless dt is a positive
    number at most the period and there are at most MAX_ROWS samples."""
    if not (isinstance(dt, (int, float)) and math.isfinite(dt) and 0 < dt <= period):
        raise SymdynError(f"excite: dt must be a positive number at most the period {period:g} s, got {dt!r}")
    rows = period / dt + 1
    if not rows <= MAX_ROWS:
        raise SymdynError(
            f"excite: a period of {period:g} s every {dt:g} s is {rows:.3g} samples, more than the CSV "
            f"may hold (MAX_ROWS = {MAX_ROWS:,}); increase dt"
        )
    return int(math.floor(period / dt + 0.5)) + 1


class _BudgetSpentError(Exception):
    """The optimiser has used its evaluations."""


def _limits(robot: Robot, given, key: str) -> np.ndarray:
    """Per-joint limit: the given values (1 or n), else the default by joint type."""
    kinds = [lk.joint for lk in robot.links if lk.mimic is None]
    if given is None:
        return np.array([DEFAULTS[key][k] for k in kinds])
    values = np.broadcast_to(np.asarray(given, dtype=float), (robot.n,)).copy()
    if not np.all((values > 0) & np.isfinite(values)):
        raise SymdynError(f"excite: {key} must be positive and finite")
    return values


def _scaled(a, b, omega, t, limits) -> tuple[np.ndarray, np.ndarray]:
    """(a, b) scaled by the largest s <= any limit allows on the sampled times."""
    traj = FourierTrajectory(np.zeros(a.shape[0]), a, b, 2.0 * np.pi / omega)
    q, qd, qdd = traj(t)
    ratios = [np.max(np.abs(x), axis=0) / lim for x, lim in zip((q, qd, qdd), limits, strict=True)]
    s = 1.0 / max(float(np.max(r)) for r in ratios)
    return a * s, b * s


def _check_settings(period, harmonics, samples, evaluations, seed) -> None:
    """SymdynError naming the first setting of `excite` out of its range."""
    low, high = PERIOD_RANGE
    if not (isinstance(period, (int, float)) and low <= period <= high):
        raise SymdynError(f"excite: the period must be from {low:g} to {high:g} s, got {period!r}")
    for name, value, low, high in (
        ("harmonics", harmonics, 1, MAX_HARMONICS),
        ("samples", samples, 2, MAX_SAMPLES),
        ("evaluations", evaluations, 1, None),
        ("seed", seed, 0, None),
    ):
        whole = isinstance(value, (int, np.integer)) and not isinstance(value, bool)
        if not whole or value < low or (high is not None and value > high):
            bound = f"from {low} to {high:,}" if high is not None else f"at least {low}"
            raise SymdynError(f"excite: {name} must be a whole number {bound}, got {value!r}")


def excite(
    robot: Robot,
    q0=None,
    q_range=None,
    qd_max=None,
    qdd_max=None,
    period: float = DEFAULTS["period"],
    harmonics: int = DEFAULTS["harmonics"],
    samples: int = DEFAULTS["samples"],
    evaluations: int = DEFAULTS["evaluations"],
    seed: int = 0,
) -> FourierTrajectory:
    """An exciting trajectory for `robot` (module docstring); the robot's parameters all numbers.

    Raises:
        SymdynError: bad limits or settings, or a robot with free parameters.
    """
    minimize = needs_scipy("optimize").minimize
    _check_settings(period, harmonics, samples, evaluations, seed)
    n = robot.n
    q0 = np.zeros(n) if q0 is None else np.broadcast_to(np.asarray(q0, dtype=float), (n,)).copy()
    limits = tuple(
        _limits(robot, v, k) for v, k in ((q_range, "q_range"), (qd_max, "qd_max"), (qdd_max, "qdd_max"))
    )
    omega = 2.0 * np.pi / period
    t = np.linspace(0.0, period, samples, endpoint=False)
    shape = (n, harmonics)

    def cost(x: np.ndarray) -> float:
        a, b = _scaled(x[: n * harmonics].reshape(shape), x[n * harmonics :].reshape(shape), omega, t, limits)
        q, qd, qdd = FourierTrajectory(q0, a, b, period)(t)
        W = base_regressor_samples(robot, q, qd, qdd).reshape(samples * n, -1)
        return float(np.log(np.linalg.cond(W)))

    best = {"f": np.inf, "x": None, "count": 0}  # the best evaluation so far, and how many

    def budgeted(x: np.ndarray) -> float:
        if best["count"] >= evaluations:
            raise _BudgetSpentError
        best["count"] += 1
        with np.errstate(all="ignore"):  # a trial whose condition number is not finite is never kept
            f = cost(x)
        if f < best["f"]:
            best.update(f=f, x=np.array(x))
        return f

    rng = np.random.default_rng(seed)
    starts = [rng.normal(size=2 * n * harmonics) for _ in range(DEFAULTS["starts"])]
    try:
        x0 = min(starts, key=budgeted)
        minimize(budgeted, x0, method="Powell", options={"xtol": 1e-3, "ftol": 1e-4})
    except _BudgetSpentError:
        pass
    f, x = best["f"], best["x"]
    if x is None:
        raise SymdynError(
            f"excite: no trial gives a finite condition number of the base regressor over {samples} "
            "samples (limits or a period so small or large that the motion does not excite every base "
            "parameter in double precision)"
        )
    a, b = _scaled(x[: n * harmonics].reshape(shape), x[n * harmonics :].reshape(shape), omega, t, limits)
    return FourierTrajectory(q0, a, b, period, condition_number=float(np.exp(f)))
