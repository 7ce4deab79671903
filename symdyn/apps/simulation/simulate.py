"""Simulation of the equations of motion (lecture slide 19).

The plant is integrated from the forward dynamics
    qdd = M(q)^-1 (tau - V(q, qd) - G(q) - F(qd))
evaluated by the robot's generated C (symdyn.compile; the generated NumPy module
without a C compiler): the robot is derived once and its library cached, so every
step is straight-line compiled code, never SymPy. Integrators
(`INTEGRATORS`), with step h and a = qdd(t, q, qd):

* "rk4" (default): the classical fourth-order Runge-Kutta scheme on (q, qd).
* "euler" (also called "lecture"): exactly the lecture's scheme of slide 19,
      q <- q + qd h + 1/2 a h^2,   qd <- qd + a h
  (explicit Euler with the position's second-order term; globally first order).
* "semi-implicit": symplectic (semi-implicit) Euler,
      qd <- qd + a h,   q <- q + qd_new h.
* "rk45", "dop853": scipy's solve_ivp (Dormand-Prince of order 5(4) and 8(5,3)),
  adaptive steps under the tolerances rtol, atol; the state is reported every dt.

The fixed-step loop runs in C (symdyn.apps.simulation.stepping) when the torque is zero,
constant, an expression of t or the computed-torque law of symdyn.apps.simulation.control; a
user-supplied Python torque function is called back from a Python loop instead.

The applied torque is a function tau(t, q, qd): zero, constants, expressions
of t (parsed by the safe parser `symdyn.model.expressions.parse_expression`, never
evaluated as Python), or any callable such as a computed-torque law
(`symdyn.apps.simulation.control`). Initial states may be one state (n,) or a batch (B, n).

The compiled dynamics live in symdyn.apps.compilation.compiled, the `Trajectory` (CSV, plot)
in symdyn.apps.simulation.trajectory and the file writing in symdyn.apps.output; their
public names are re-exported here.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ...errors import SymdynError
from ...model.quaternion_norm import check_quaternions, quaternion_norms
from ...progress import Steps
from ..compilation.compiled import CompiledDynamics, compiled_dynamics, with_parameters
from ..compilation.singular import divergence_error
from ..output import write_atomic
from . import stepping
from .floating_stepping import floating_sizes, run_floating
from .stepping import ADAPTIVE, INTEGRATORS, sample_times, torque_rows
from .trajectory import Trajectory, plot_trajectory

if TYPE_CHECKING:
    import sympy as sp

    from ...model.robot import Robot

__all__ = [
    "INTEGRATORS",
    "ADAPTIVE",
    "CompiledDynamics",
    "Trajectory",
    "compiled_dynamics",
    "with_parameters",
    "time_expressions",
    "lambdify_time",
    "torque_function",
    "torque_table",
    "initial_state",
    "simulate",
    "write_atomic",
    "plot_trajectory",
    "TIME",  # noqa: F822 (module __getattr__)
]


def __getattr__(name: str):
    """TIME, the time symbol of torque and reference expressions (SymPy is imported on first use)."""
    if name == "TIME":
        import sympy as sp

        return sp.Symbol("t")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: The most steps a run may have (its arrays hold MAX_STEPS + 1 states).
MAX_STEPS = 10_000_000
#: Runs of at least this many steps show a progress bar by default (when stderr is a terminal).
PROGRESS_MIN_STEPS = 2000


# --------------------------------------------------------------------------- torque inputs


def time_expressions(values: Sequence, n: int, what: str = "tau", broadcast: bool = True) -> list[sp.Expr]:
    """Parse n numbers or expressions of t (safe parser; only the name t is allowed).

    With `broadcast`, a single value applies to every joint.
    """
    import sympy as sp

    from ...model.expressions import parse_expression

    time = sp.Symbol("t")
    values = list(values)
    if broadcast and len(values) == 1 and n > 1:
        values = values * n
    if len(values) != n:
        raise SymdynError(f"{what}: expected {n} values (one per joint), got {len(values)}")
    exprs = []
    for i, v in enumerate(values, 1):
        e = v if isinstance(v, sp.Basic) else parse_expression(v, field=f"{what}[{i}]")
        extra = sorted(str(s) for s in e.free_symbols if s != time)
        if extra:
            raise SymdynError(f"{what}[{i}]: unknown name(s) {', '.join(extra)}: only t (time, s) may appear")
        exprs.append(e)
    return exprs


def lambdify_time(exprs: Sequence[sp.Expr], what: str = "tau") -> Callable[[float], np.ndarray]:
    """A function t -> array (n,) (or (n, len(t)) for an array t) of the parsed expressions.

    Evaluated in floating point (NumPy, warnings silenced): a value that is not a finite real
    number at some t (1/t at t = 0, sqrt(t - 1) before t = 1, an overflow) raises SymdynError
    naming `what`[i], the expression and the first such t, instead of a Python exception or
    NaN entering the simulation.
    """
    import sympy as sp

    funcs = [sp.lambdify(sp.Symbol("t"), e, modules="numpy") for e in exprs]

    def f(t):
        ts = np.asarray(t, dtype=float)
        rows = []
        for i, (g, e) in enumerate(zip(funcs, exprs, strict=True), 1):
            with np.errstate(all="ignore"):
                try:
                    v = np.asarray(g(ts))
                except (ArithmeticError, ValueError, TypeError):  # e.g. 0.0 ** -1 on a Python float
                    v = np.full(ts.shape, np.nan)
            if np.iscomplexobj(v):
                v = np.where(v.imag == 0, v.real, np.nan)
            v = np.broadcast_to(v.astype(float), ts.shape)
            bad = ~np.isfinite(v)
            if bad.any():
                at = float(ts.flat[np.flatnonzero(bad)[0]]) if ts.ndim else float(ts)
                text = str(e) if len(str(e)) <= 60 else str(e)[:57] + "..."
                raise SymdynError(f"{what}[{i}] = {text} is not a finite real number at t = {at:g} s")
            rows.append(v)
        return np.array(rows)

    return f


def _constants(tau, n: int) -> np.ndarray | None:
    """n torques given as plain numbers (one: every joint), without parsing; else None."""
    values = [tau] if isinstance(tau, (int, float)) else tau
    if not isinstance(values, (list, tuple, np.ndarray)) or isinstance(tau, bool):
        return None
    if not all(isinstance(v, (int, float, np.floating)) and not isinstance(v, bool) for v in values):
        return None
    values = [float(v) for v in values]
    if len(values) == 1 and n > 1:
        values = values * n
    if len(values) != n:
        raise SymdynError(f"tau: expected {n} values (one per joint), got {len(values)}")
    return np.array(values)


def torque_function(tau, n: int) -> Callable:
    """tau(t, q, qd) from None (zero), a callable, or n numbers / expressions of t."""
    if tau is None:
        zero = np.zeros(n)
        return lambda t, q, qd: zero
    if callable(tau):
        return tau
    const = _constants(tau, n)
    if const is not None:
        return lambda t, q, qd: const
    if isinstance(tau, str):
        tau = [tau]
    exprs = time_expressions(tau, n, "tau")
    if all(not e.free_symbols for e in exprs):
        const = np.array([float(e) for e in exprs])
        return lambda t, q, qd: const
    f = lambdify_time(exprs)
    return lambda t, q, qd: f(t)


# --------------------------------------------------------------------------- integration


def initial_state(x, n: int, name: str) -> np.ndarray:
    """`x` as a finite float array of one state (n,) or a batch (B, n); else SymdynError naming `name`."""
    try:
        a = np.array(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise SymdynError(f"{name}: expected numbers, got {x!r}") from exc
    if a.ndim == 0 or a.ndim > 2 or a.shape[-1] != n:
        raise SymdynError(f"{name} must have {n} entries (one per joint), or shape (B, {n}); got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise SymdynError(f"{name} must be finite")
    return a


def torque_table(tau, n: int, rows: np.ndarray) -> np.ndarray | None:
    """The torque at the table's times (3 per step, symdyn.apps.simulation.stepping), or None for a
    Python callable."""
    if callable(tau):
        return None
    if tau is None:
        return np.zeros((len(rows), n))
    const = _constants(tau, n)
    if const is not None:
        return np.tile(const, (len(rows), 1))
    exprs = time_expressions([tau] if isinstance(tau, str) else tau, n, "tau")
    if all(not e.free_symbols for e in exprs):
        return np.tile(np.array([float(e) for e in exprs]), (len(rows), 1))
    return np.ascontiguousarray(lambdify_time(exprs)(rows).T)


def _in_c(plant, scheme, q, qd, t, h, tau, tau_at, bar):
    """(Q, QD, U) of the whole run with the stepping loop in C, or None when it cannot run there."""
    rows = torque_rows(t, h)
    table, controller, reference = torque_table(tau, plant.n, rows), None, None
    if table is None:
        law = getattr(tau, "tracking", None)  # a computed-torque law (symdyn.apps.simulation.control)
        if law is None:
            return None
        controller, ref = law
        reference = np.concatenate(ref(rows), axis=1)
    batch = q.reshape(-1, plant.n), qd.reshape(-1, plant.n)
    runs = []
    for q0, qd0 in zip(*batch, strict=True):
        out = stepping.run(plant, scheme, q0, qd0, h, t, table, controller, reference, bar)
        if out is None:
            return None
        Q, QD, U = out
        U[-1] = tau_at(t[-1], Q[-1], QD[-1])
        runs.append(out)
    shape = (len(t), *q.shape)
    return tuple(np.stack([r[i] for r in runs], axis=1).reshape(shape) for i in range(3))


def _in_python(plant, scheme, q, qd, t, h, tau_at, bar):
    """(Q, QD, U) with the loop in Python, the dynamics compiled (user-supplied torque functions)."""
    steps = len(h)

    def accel(t, q, qd):
        u = tau_at(t, q, qd)
        return plant.forward_dynamics(q, qd, u), u

    shape = (steps + 1, *q.shape)
    Q, QD, U = np.empty(shape), np.empty(shape), np.empty(shape)
    Q[0], QD[0] = q, qd
    with np.errstate(all="ignore"):
        for k in range(steps):
            tk, hk = t[k], h[k]
            a, U[k] = accel(tk, q, qd)
            if scheme == "rk4":
                k1q, k1v = qd, a
                k2q = qd + 0.5 * hk * k1v
                k2v = accel(tk + 0.5 * hk, q + 0.5 * hk * k1q, k2q)[0]
                k3q = qd + 0.5 * hk * k2v
                k3v = accel(tk + 0.5 * hk, q + 0.5 * hk * k2q, k3q)[0]
                k4q = qd + hk * k3v
                k4v = accel(tk + hk, q + hk * k3q, k4q)[0]
                q = q + hk / 6.0 * (k1q + 2 * k2q + 2 * k3q + k4q)
                qd = qd + hk / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
            elif scheme == "euler":
                q = q + qd * hk + 0.5 * a * hk * hk
                qd = qd + a * hk
            else:  # semi-implicit (symplectic) Euler
                qd = qd + a * hk
                q = q + qd * hk
            if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
                raise divergence_error(plant, t[k + 1], Q[k])
            Q[k + 1], QD[k + 1] = q, qd
            bar.update(k + 1, t[k + 1])
        U[steps] = tau_at(t[steps], q, qd)
    return Q, QD, U


def _adaptive(plant, method, q, qd, t, tau_at, rtol, atol):
    """(Q, QD, U) from scipy's solve_ivp (RK45 or DOP853 with error control), sampled at t."""
    try:
        from scipy.integrate import solve_ivp
    except ImportError:
        raise SymdynError(f"the {method} integrator needs scipy (pip install 'symdyn[sim]')") from None
    n = plant.n
    starts = list(zip(q.reshape(-1, n), qd.reshape(-1, n), strict=True))
    Q, QD = np.empty((len(t), len(starts), n)), np.empty((len(t), len(starts), n))

    def rhs(s, y):
        x, v = y[:n], y[n:]
        return np.concatenate([v, plant.forward_dynamics(x, v, tau_at(s, x, v))])

    for b, (q0, qd0) in enumerate(starts):
        with np.errstate(all="ignore"):
            sol = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([q0, qd0]), method=method.upper(), t_eval=t,
                            rtol=rtol, atol=atol)  # fmt: skip
        if not sol.success or not np.all(np.isfinite(sol.y)):
            raise SymdynError(f"the {method} integrator failed: {sol.message}")
        Q[:, b], QD[:, b] = sol.y[:n].T, sol.y[n:].T
    Q, QD = Q.reshape((len(t), *q.shape)), QD.reshape((len(t), *q.shape))
    U = np.empty_like(Q)
    for k, tk in enumerate(t):
        U[k] = tau_at(tk, Q[k], QD[k])
    return Q, QD, U


def _floating(plant, sizes, q0, v0, duration, dt, tau, integrator) -> Trajectory:
    """A floating robot's run (symdyn.apps.simulation.floating_stepping): q0 of NQ, v0 of NV, one state."""
    nq, nv = sizes
    q = initial_state(q0, nq, "q0")
    v = np.zeros(nv) if v0 is None else initial_state(v0, nv, "qd0")
    if q.ndim != 1 or v.ndim != 1:
        raise SymdynError(f"robot '{plant.robot.name}' has a floating base: give one initial state")
    check_quaternions(q, "q0")  # then a unit quaternion: the one the run's integrate keeps
    q[3:7] /= quaternion_norms(q)
    t, h = sample_times(duration, dt)
    table = torque_table(tau, nv, torque_rows(t, h))
    torque = torque_function(tau, nv) if table is None else None

    def tau_at(row, tk, q, v):
        if table is not None:
            return table[row]
        return np.broadcast_to(np.asarray(torque(tk, q, v), dtype=float), v.shape)

    scheme = "euler" if integrator == "lecture" else integrator
    Q, V, U = run_floating(plant, scheme, q, v, h, t, tau_at)
    A = np.asarray(plant.forward_dynamics(Q, V, U), dtype=float)  # for the CSV: an identification log
    return Trajectory(plant.robot, t, Q, V, U, scheme, plant=plant, qdd=A)


def simulate(
    robot: Robot | CompiledDynamics,
    q0,
    qd0=None,
    duration: float = 1.0,
    dt: float = 1e-3,
    tau=None,
    integrator: str = "rk4",
    params=None,
    progress: bool | None = None,
    rtol: float = 1e-6,
    atol: float = 1e-9,
) -> Trajectory:
    """Integrate the robot's forward dynamics from (q0, qd0) over [0, duration] with step dt.

    tau: None (zero torque), n numbers or expressions of t (strings), or a callable
    tau(t, q, qd) -> (n,) or (B, n). If duration is not a multiple of dt, the last
    step is shorter. The fixed-step integrators run their whole loop in C unless tau is
    a Python callable (a computed-torque law of symdyn.apps.simulation.control runs in C too). rk45
    and dop853 (scipy's solve_ivp) adapt their step to the tolerances rtol, atol and
    report the state every dt. progress: True/False, or None for a bar on stderr when it
    is a terminal, the run has at least PROGRESS_MIN_STEPS steps and no report is silenced
    (symdyn.progress.Steps). Raises SymdynError
    for bad input and when the state stops being finite (diverged).
    """
    plant = compiled_dynamics(robot, params)
    n = plant.n
    if integrator not in INTEGRATORS:
        raise SymdynError(f"unknown integrator '{integrator}' (one of {', '.join(INTEGRATORS)})")
    for name, v in (("duration", duration), ("dt", dt), ("rtol", rtol), ("atol", atol)):
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v <= 0:
            raise SymdynError(f"{name} must be a positive number, got {v!r}")
    if dt > duration:
        raise SymdynError(f"dt ({dt}) is longer than the duration ({duration})")
    ratio = duration / dt
    if not ratio < MAX_STEPS + 1:  # also an infinite ratio (dt = 5e-324)
        raise SymdynError(
            f"duration {duration:g} s with dt {dt:g} s is {ratio:.3g} steps, too many (at most "
            f"{MAX_STEPS}); increase dt"
        )
    steps = math.ceil(ratio - 1e-9)
    if steps > MAX_STEPS:
        raise SymdynError(f"{steps} steps is too many (at most {MAX_STEPS}); increase dt")
    if "forward_dynamics" not in plant.functions:
        raise SymdynError(
            f"robot '{plant.robot.name}': no forward dynamics (M(q) is singular), cannot simulate"
        )
    sizes = floating_sizes(plant)
    if sizes is not None:
        return _floating(plant, sizes, q0, qd0, duration, dt, tau, integrator)
    q = initial_state(q0, n, "q0")
    qd = np.zeros_like(q) if qd0 is None else initial_state(qd0, n, "qd0")
    q, qd = np.broadcast_arrays(q, qd)
    q, qd = q.copy(), qd.copy()
    torque = torque_function(tau, n)

    def tau_at(t, q, qd):
        return np.broadcast_to(np.asarray(torque(t, q, qd), dtype=float), q.shape)

    t, h = sample_times(duration, dt)
    scheme = "euler" if integrator == "lecture" else integrator
    if scheme in ADAPTIVE:
        Q, QD, U = _adaptive(plant, scheme, q, qd, t, tau_at, rtol, atol)
        return Trajectory(plant.robot, t, Q, QD, U, scheme, plant=plant)
    if progress is None and steps < PROGRESS_MIN_STEPS:
        progress = False
    bar = Steps("simulate", steps, progress, until=duration)
    try:
        out = _in_c(plant, scheme, q, qd, t, h, tau, tau_at, bar)
        Q, QD, U = out if out is not None else _in_python(plant, scheme, q, qd, t, h, tau_at, bar)
    finally:
        bar.close()
    return Trajectory(plant.robot, t, Q, QD, U, scheme, plant=plant)
