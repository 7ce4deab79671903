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

from ..errors import SymdynError
from ..model.robot import Robot
from .compiled import CompiledDynamics, compiled_dynamics
from .simulate import TIME, lambdify_time, simulate, time_expressions
from .trajectory import Trajectory

__all__ = ["Reference", "ComputedTorque", "TrackingLaw", "pd_gains", "track"]


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
        self._f = [lambdify_time(x) for x in (self.exprs, self.d_exprs, self.dd_exprs)]

    @property
    def n(self) -> int:
        return len(self.exprs)

    def __call__(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        out = [f(t) for f in self._f]  # each (n,) or (n, len(t))
        return tuple(np.moveaxis(x, 0, -1) for x in out)  # type: ignore[return-value]


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
