"""Computed-torque control (lecture slide 20): feedforward dynamic compensation with a PD loop.

    tau = M(q) (qdd_ref + Kp (q_ref - q) + Kd (qd_ref - qd)) + V(q, qd) + G(q) [+ F(qd)]

M, V, G, F come from the controller's *model*, a Robot that may carry other
parameter values than the plant (model error). With an exact model the plant
becomes linear and decoupled: the error e = q_ref - q obeys
    e'' + Kd e' + Kp e = 0,
so with Kp = omega^2 and Kd = 2 zeta omega (`pd_gains`) every joint's error
decays like exp(-zeta omega t) (for zeta <= 1).

References q_ref(t) are numbers or expressions of t parsed by the safe parser;
qd_ref and qdd_ref are their symbolic derivatives (`Reference`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy as sp

from ...errors import SymdynError
from ...model.robot import Robot
from ..compilation.compiled import CompiledDynamics, compiled_dynamics
from .simulate import TIME, lambdify_time, simulate, time_expressions
from .trajectory import Trajectory

__all__ = ["Reference", "SampledReference", "ComputedTorque", "TrackingLaw", "pd_gains", "track"]


def pd_gains(omega: float, zeta: float = 1.0) -> tuple[float, float]:
    """(Kp, Kd) = (omega^2, 2 zeta omega): natural frequency omega (rad/s), damping ratio zeta."""
    if not omega > 0 or not zeta >= 0:
        raise SymdynError(f"pd_gains needs omega > 0 and zeta >= 0, got {omega}, {zeta}")
    return omega * omega, 2.0 * zeta * omega


class Reference:
    """A joint-space reference q_ref(t), one number or expression of t per joint.

    `exprs`, `d_exprs`, `dd_exprs` are q_ref, qd_ref = dq_ref/dt and qdd_ref as SymPy
    expressions; calling the reference at t (a number or an array of times) gives the
    three as arrays (n,) or (len(t), n).
    """

    def __init__(self, exprs: Sequence, n: int | None = None) -> None:
        exprs = list(exprs) if not isinstance(exprs, str) else [exprs]
        n = len(exprs) if n is None else n
        self.exprs = time_expressions(exprs, n, "reference", broadcast=False)
        self.d_exprs = [sp.diff(e, TIME) for e in self.exprs]
        self.dd_exprs = [sp.diff(e, TIME) for e in self.d_exprs]
        self._f = [
            lambdify_time(x, what)
            for x, what in zip(
                (self.exprs, self.d_exprs, self.dd_exprs),
                ("reference", "d/dt reference", "d2/dt2 reference"),
                strict=True,
            )
        ]

    @property
    def n(self) -> int:
        return len(self.exprs)

    def __call__(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        out = [f(t) for f in self._f]  # each (n,) or (n, len(t))
        return tuple(np.moveaxis(x, 0, -1) for x in out)  # type: ignore[return-value]


class SampledReference:
    """A joint-space reference given by samples (t_k, q_k, qd_k, qdd_k), e.g. a CSV file.

    Between samples q_ref is the cubic Hermite interpolant of (q_k, qd_k), qd_ref that of
    (qd_k, qdd_k) and qdd_ref is linear, so a trajectory sampled from a smooth one (such as
    `symdyn excite`'s Fourier series) is followed with an O(h^4) error in q_ref for a sample
    spacing h. Times outside [t_0, t_N] are an error, not an extrapolation.
    """

    def __init__(self, t, q, qd, qdd, where: str = "reference") -> None:
        self.t = np.asarray(t, dtype=float)
        self.q, self.qd, self.qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
        if self.t.ndim != 1 or len(self.t) < 2 or np.any(np.diff(self.t) <= 0):
            raise SymdynError(f"{where}: the times must increase strictly (at least two samples)")
        self.where = where

    @classmethod
    def from_csv(cls, path, n: int) -> SampledReference:
        """The columns t, q1..qn and (optionally) qd1..qdn, qdd1..qddn of a CSV file
        (identification.measurements.read_measurements: without them, a Savitzky-Golay estimate)."""
        from ..identification.measurements import read_measurements

        data = read_measurements(path, n, torques=False)
        return cls(data.t, data.q, data.qd, data.qdd, where=str(path))

    @property
    def n(self) -> int:
        return self.q.shape[1]

    @property
    def span(self) -> tuple[float, float]:
        return float(self.t[0]), float(self.t[-1])

    def __call__(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ts = np.atleast_1d(np.asarray(t, dtype=float))
        lo, hi = self.span
        if np.any(ts < lo - 1e-12) or np.any(ts > hi + 1e-12):
            raise SymdynError(f"{self.where}: the reference covers t in [{lo:g}, {hi:g}] s only")
        k = np.clip(np.searchsorted(self.t, ts, side="right") - 1, 0, len(self.t) - 2)
        h = (self.t[k + 1] - self.t[k])[:, None]
        s = ((ts - self.t[k])[:, None]) / h
        q_ref = _hermite(self.q[k], self.q[k + 1], self.qd[k] * h, self.qd[k + 1] * h, s)
        qd_ref = _hermite(self.qd[k], self.qd[k + 1], self.qdd[k] * h, self.qdd[k + 1] * h, s)
        qdd_ref = (1 - s) * self.qdd[k] + s * self.qdd[k + 1]
        if np.ndim(t) == 0:
            return q_ref[0], qd_ref[0], qdd_ref[0]
        return q_ref, qd_ref, qdd_ref


def _hermite(y0, y1, m0, m1, s):
    """The cubic Hermite interpolant at s in [0, 1] of values y0, y1 and scaled slopes m0, m1."""
    s2, s3 = s * s, s * s * s
    return (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * m1


def _gain(K, n: int, name: str) -> np.ndarray:
    """A gain matrix from a scalar, n diagonal entries, or an n x n matrix."""
    try:
        a = np.array(K, dtype=float)
    except (TypeError, ValueError) as exc:
        raise SymdynError(f"{name}: expected numbers, got {K!r}") from exc
    if a.ndim == 0 or a.shape == (1,):
        a = np.full(n, float(a.reshape(-1)[0]))
    if a.shape == (n,):
        a = np.diag(a)
    if a.shape != (n, n) or not np.all(np.isfinite(a)):
        raise SymdynError(f"{name} must be a number, {n} numbers or an {n} x {n} matrix; got shape {a.shape}")
    return a


class ComputedTorque:
    """The computed-torque law of slide 20 over a model robot.

    model: a Robot (free parameters given by `params`) or a CompiledDynamics; it may
    differ from the plant. Kp, Kd: scalars, per-joint values or n x n matrices.
    friction: also compensate the model's friction F(qd) (default True).
    """

    def __init__(self, model: Robot | CompiledDynamics, Kp, Kd, params=None, friction: bool = True) -> None:
        self.model = compiled_dynamics(model, params)
        n = self.model.n
        self.Kp = _gain(Kp, n, "Kp")
        self.Kd = _gain(Kd, n, "Kd")
        self.friction = friction

    @property
    def n(self) -> int:
        return self.model.n

    def command(self, q, qd, q_ref, qd_ref, qdd_ref) -> np.ndarray:
        """The commanded acceleration a = qdd_ref + Kp (q_ref - q) + Kd (qd_ref - qd)."""
        e = np.asarray(q_ref, dtype=float) - q
        ed = np.asarray(qd_ref, dtype=float) - qd
        return qdd_ref + e @ self.Kp.T + ed @ self.Kd.T

    def torque(self, q, qd, q_ref, qd_ref, qdd_ref) -> np.ndarray:
        """tau = M(q) a + V(q, qd) + G(q) (+ F(qd)): one state (n,) or a batch (B, n)."""
        q = np.asarray(q, dtype=float)
        qd = np.asarray(qd, dtype=float)
        a = self.command(q, qd, q_ref, qd_ref, qdd_ref)
        tau = self.model.inverse_dynamics(q, qd, a)  # M a + V + G + F in one generated call
        if not self.friction:
            tau = tau - self.model.friction(qd)
        return tau

    __call__ = torque

    def law(self, reference: Reference):
        """tau(t, q, qd) tracking `reference`: the torque function `simulate` takes.

        simulate recognises it (its `tracking` attribute) and runs the law inside its C loop.
        """
        if reference.n != self.n:
            raise SymdynError(f"the reference has {reference.n} joints, the model {self.n}")
        return TrackingLaw(self, reference)


class TrackingLaw:
    """The torque function tau(t, q, qd) of a ComputedTorque tracking a Reference."""

    def __init__(self, controller: ComputedTorque, reference: Reference) -> None:
        self.tracking = (controller, reference)

    def __call__(self, t, q, qd) -> np.ndarray:
        controller, reference = self.tracking
        r, rd, rdd = reference(t)
        return controller.torque(q, qd, r, rd, rdd)


def track(
    plant: Robot | CompiledDynamics,
    reference: Reference,
    controller: ComputedTorque,
    q0=None,
    qd0=None,
    duration: float = 1.0,
    dt: float = 1e-3,
    integrator: str = "rk4",
    params=None,
    progress: bool | None = None,
    rtol: float = 1e-6,
    atol: float = 1e-9,
) -> Trajectory:
    """Simulate the plant under `controller` tracking `reference` (rtol, atol: rk45 and dop853 only).

    q0, qd0 default to the reference's initial position and velocity. The result
    carries q_ref and qd_ref at the sample times.
    """
    r0, rd0, _ = reference(0.0)
    traj = simulate(
        plant,
        r0 if q0 is None else q0,
        rd0 if qd0 is None else qd0,
        duration=duration,
        dt=dt,
        tau=controller.law(reference),
        integrator=integrator,
        params=params,
        progress=progress,
        rtol=rtol,
        atol=atol,
    )
    q_ref, qd_ref, _ = reference(traj.t)
    if traj.q.ndim == 3:
        q_ref, qd_ref = q_ref[:, None, :], qd_ref[:, None, :]
    traj.q_ref = np.broadcast_to(q_ref, traj.q.shape).copy()
    traj.qd_ref = np.broadcast_to(qd_ref, traj.q.shape).copy()
    return traj
