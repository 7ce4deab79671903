"""Simulation of the equations of motion (lecture slide 19).

The plant is integrated from the forward dynamics
    qdd = M(q)^-1 (tau - V(q, qd) - G(q) - F(qd))
evaluated by the generated NumPy module of the robot (`symdyn.codegen`,
target "python"): the robot is derived once, its module rendered in memory
and loaded, so every step is straight-line NumPy, never SymPy. Integrators
(`INTEGRATORS`), with step h and a = qdd(t, q, qd):

* "rk4" (default): the classical fourth-order Runge-Kutta scheme on (q, qd).
* "euler" (also called "lecture"): exactly the lecture's scheme of slide 19,
      q <- q + qd h + 1/2 a h^2,   qd <- qd + a h
  (explicit Euler with the position's second-order term; globally first order).
* "semi-implicit": symplectic (semi-implicit) Euler,
      qd <- qd + a h,   q <- q + qd_new h.

The applied torque is a function tau(t, q, qd): zero, constants, expressions
of t (parsed by the safe parser `symdyn.model.expressions.parse_expression`, never
evaluated as Python), or any callable such as a computed-torque law
(`symdyn.apps.control`). Initial states may be one state (n,) or a batch (B, n).
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
import types
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import sympy as sp

from ..errors import SymdynError
from ..model.expressions import parse_expression
from ..model.robot import Robot

__all__ = [
    "INTEGRATORS",
    "CompiledDynamics",
    "Trajectory",
    "compiled_dynamics",
    "with_parameters",
    "time_expressions",
    "torque_function",
    "simulate",
    "write_atomic",
    "plot_trajectory",
    "TIME",
]

#: The integrators; "lecture" is another name for "euler" (the scheme of slide 19).
INTEGRATORS = ("rk4", "euler", "lecture", "semi-implicit")
#: The time symbol of torque and reference expressions.
TIME = sp.Symbol("t")
#: Runs of at least this many steps show a progress bar by default (when stderr is a terminal).
PROGRESS_MIN_STEPS = 2000


# --------------------------------------------------------------------------- compiled dynamics


@lru_cache(maxsize=32)
def _generated_module(robot: Robot) -> types.ModuleType:
    """The NumPy module symdyn generates for `robot`, rendered in memory and loaded."""
    from ..codegen import render

    files = render(robot, targets=("python",))
    ((name, text),) = ((k, v) for k, v in files.items() if k.endswith("_numpy.py"))
    module = types.ModuleType(name[:-3])
    module.__file__ = f"<symdyn generated {name}>"
    # the text is symdyn's own output for a parsed robot, not user-supplied code
    exec(compile(text, module.__file__, "exec"), module.__dict__)
    return module


def with_parameters(robot: Robot, values: Mapping[str, float] | None) -> Robot:
    """`robot` with the named parameters set to numbers (free ones or ones the file gave a value).

    The result has those parameters as values (no longer free). A value the file
    wrote as an expression of another parameter keeps the number it had.
    """
    if not values:
        return robot
    known = {str(s): s for s in (*robot.params, *(s for s, _ in robot.values))}
    unknown = [k for k in values if str(k) not in known]
    if unknown:
        names = ", ".join(sorted(known)) or "none"
        raise SymdynError(f"unknown parameter(s) {', '.join(map(str, unknown))} (robot parameters: {names})")
    numbers = {known[str(k)]: sp.Float(float(v), 17) for k, v in values.items()}
    old = {s: sp.sympify(v).xreplace(numbers) for s, v in robot.values}
    old.update(numbers)
    return replace(
        robot,
        params=tuple(p for p in robot.params if p not in numbers),
        values=tuple(old.items()),
    )


class CompiledDynamics:
    """The generated NumPy functions of a robot, bound to values of its free parameters.

    Every method accepts one state (n,) or a batch (B, n), like the generated module.
    """

    def __init__(self, robot: Robot, params=None) -> None:
        self.robot = robot
        self.module = _generated_module(robot)
        values = robot.param_values(params) if robot.params else {}
        by_name = {str(k): v for k, v in values.items()}
        names = self.module.PARAM_NAMES
        self.p = np.array([by_name[n] for n in names], dtype=float) if names else None

    @property
    def n(self) -> int:
        return self.robot.n

    def mass_matrix(self, q) -> np.ndarray:
        return self.module.mass_matrix(q, self.p)

    def coriolis(self, q, qd) -> np.ndarray:
        """V(q, qd) = C(q, qd) qd."""
        return self.module.coriolis(q, qd, self.p)

    def gravity(self, q) -> np.ndarray:
        return self.module.gravity(q, self.p)

    def friction(self, qd) -> np.ndarray:
        return self.module.friction(qd, self.p)

    def inverse_dynamics(self, q, qd, qdd) -> np.ndarray:
        return self.module.inverse_dynamics(q, qd, qdd, self.p)

    def forward_dynamics(self, q, qd, tau) -> np.ndarray:
        return self.module.forward_dynamics(q, qd, tau, self.p)


def compiled_dynamics(robot: Robot | CompiledDynamics, params=None) -> CompiledDynamics:
    """A CompiledDynamics for a Robot (or the given one unchanged when params is None)."""
    if isinstance(robot, CompiledDynamics):
        if params is not None:
            return CompiledDynamics(robot.robot, params)
        return robot
    if not isinstance(robot, Robot):
        raise SymdynError(f"expected a Robot, not {type(robot).__name__}")
    return CompiledDynamics(robot, params)


# --------------------------------------------------------------------------- torque inputs


def time_expressions(values: Sequence, n: int, what: str = "tau", broadcast: bool = True) -> list[sp.Expr]:
    """Parse n numbers or expressions of t (safe parser; only the name t is allowed).

    With `broadcast`, a single value applies to every joint.
    """
    values = list(values)
    if broadcast and len(values) == 1 and n > 1:
        values = values * n
    if len(values) != n:
        raise SymdynError(f"{what}: expected {n} values (one per joint), got {len(values)}")
    exprs = []
    for i, v in enumerate(values, 1):
        e = v if isinstance(v, sp.Basic) else parse_expression(v, field=f"{what}[{i}]")
        extra = sorted(str(s) for s in e.free_symbols if s != TIME)
        if extra:
            raise SymdynError(f"{what}[{i}]: unknown name(s) {', '.join(extra)}: only t (time, s) may appear")
        exprs.append(e)
    return exprs


def _lambdify_time(exprs: Sequence[sp.Expr]) -> Callable[[float], np.ndarray]:
    """A function t -> array (n,) (or (n, len(t)) for an array t) of the parsed expressions."""
    funcs = [sp.lambdify(TIME, e, modules="numpy") for e in exprs]

    def f(t):
        return np.array([np.broadcast_to(np.asarray(g(t), dtype=float), np.shape(t)) for g in funcs])

    return f


def torque_function(tau, n: int) -> Callable:
    """tau(t, q, qd) from None (zero), a callable, or n numbers / expressions of t."""
    if tau is None:
        zero = np.zeros(n)
        return lambda t, q, qd: zero
    if callable(tau):
        return tau
    if isinstance(tau, str):
        tau = [tau]
    exprs = time_expressions(tau, n, "tau")
    if all(not e.free_symbols for e in exprs):
        const = np.array([float(e) for e in exprs])
        return lambda t, q, qd: const
    f = _lambdify_time(exprs)
    return lambda t, q, qd: f(t)


# --------------------------------------------------------------------------- trajectories


@dataclass
class Trajectory:
    """A simulated run: sample times t (N,), states q, qd and torque tau (N, n), or (N, B, n) for a batch.

    tau[k] is the torque at (t_k, q_k, qd_k), the one applied at the start of step k.
    `q_ref`, `qd_ref` hold a tracked reference at the same times (None without one).
    """

    robot: Robot
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    tau: np.ndarray
    integrator: str
    q_ref: np.ndarray | None = None
    qd_ref: np.ndarray | None = None

    @property
    def n(self) -> int:
        return self.robot.n

    def csv_text(self) -> str:
        """Columns t, q1..qn, qd1..qdn, one row per sample, full double precision."""
        if self.q.ndim != 2:
            raise SymdynError("CSV output holds one trajectory, not a batch")
        n = self.n
        header = ["t"] + [f"q{i}" for i in range(1, n + 1)] + [f"qd{i}" for i in range(1, n + 1)]
        rows = np.column_stack([self.t, self.q, self.qd])
        lines = [",".join(header)]
        lines += [",".join(f"{x:.17g}" for x in row) for row in rows]
        return "\n".join(lines) + "\n"

    def write_csv(self, path: str | os.PathLike) -> Path:
        """Write csv_text() atomically (temporary file in the same folder, then rename)."""
        return write_atomic(path, self.csv_text())


def write_atomic(path: str | os.PathLike, content: str | bytes) -> Path:
    """Write a file all at once: a temporary file beside it, then os.replace."""
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise SymdynError(f"{target}: folder {folder} does not exist")
    if target.is_dir():
        raise SymdynError(f"{target}: is a folder")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(content.encode() if isinstance(content, str) else content)
        os.chmod(tmp, 0o644)
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return target


class _Progress:
    """A one-line progress bar on stderr: `simulate [#####-----]  50%  t = 1.50 / 3.00 s`."""

    def __init__(self, total_steps: int, duration: float, enabled: bool, stream=None) -> None:
        self.total = max(total_steps, 1)
        self.duration = duration
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self.shown = -1

    def update(self, step: int, t: float) -> None:
        if not self.enabled:
            return
        pct = int(100 * step / self.total)
        if pct == self.shown:
            return
        self.shown = pct
        filled = pct * 30 // 100
        bar = "#" * filled + "-" * (30 - filled)
        self.stream.write(f"\rsimulate [{bar}] {pct:3d}%  t = {t:.3f} / {self.duration:.3f} s")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled and self.shown >= 0:
            self.stream.write("\n")
            self.stream.flush()


def _state(x, n: int, name: str) -> np.ndarray:
    try:
        a = np.array(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise SymdynError(f"{name}: expected numbers, got {x!r}") from exc
    if a.ndim == 0 or a.ndim > 2 or a.shape[-1] != n:
        raise SymdynError(f"{name} must have {n} entries (one per joint), or shape (B, {n}); got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise SymdynError(f"{name} must be finite")
    return a


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
) -> Trajectory:
    """Integrate the robot's forward dynamics from (q0, qd0) over [0, duration] with step dt.

    tau: None (zero torque), n numbers or expressions of t (strings), or a callable
    tau(t, q, qd) -> (n,) or (B, n). If duration is not a multiple of dt, the last
    step is shorter. progress: True/False, or None for a bar on stderr when it is a
    terminal and the run has at least PROGRESS_MIN_STEPS steps. Raises SymdynError for
    bad input and when the state stops being finite (diverged).
    """
    plant = compiled_dynamics(robot, params)
    n = plant.n
    if integrator not in INTEGRATORS:
        raise SymdynError(f"unknown integrator '{integrator}' (one of {', '.join(INTEGRATORS)})")
    for name, v in (("duration", duration), ("dt", dt)):
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v <= 0:
            raise SymdynError(f"{name} must be a positive number, got {v!r}")
    if dt > duration:
        raise SymdynError(f"dt ({dt}) is longer than the duration ({duration})")
    steps = math.ceil(duration / dt - 1e-9)
    if steps > 10_000_000:
        raise SymdynError(f"{steps} steps is too many (at most 10000000); increase dt")
    q = _state(q0, n, "q0")
    qd = np.zeros_like(q) if qd0 is None else _state(qd0, n, "qd0")
    q, qd = np.broadcast_arrays(q, qd)
    q, qd = q.copy(), qd.copy()
    torque = torque_function(tau, n)

    def tau_at(t, q, qd):
        return np.broadcast_to(np.asarray(torque(t, q, qd), dtype=float), q.shape)

    def accel(t, q, qd):
        u = tau_at(t, q, qd)
        return plant.forward_dynamics(q, qd, u), u

    shape = (steps + 1, *q.shape)
    T = np.empty(steps + 1)
    Q, QD, U = np.empty(shape), np.empty(shape), np.empty(shape)
    T[0], Q[0], QD[0] = 0.0, q, qd
    if progress is None:
        progress = steps >= PROGRESS_MIN_STEPS and sys.stderr.isatty()
    bar = _Progress(steps, duration, bool(progress))
    scheme = "euler" if integrator == "lecture" else integrator
    t = 0.0
    try:
        with np.errstate(all="ignore"):
            for k in range(steps):
                h = min(dt, duration - t) if k == steps - 1 else dt
                a, U[k] = accel(t, q, qd)
                if scheme == "rk4":
                    k1q, k1v = qd, a
                    k2q = qd + 0.5 * h * k1v
                    k2v = accel(t + 0.5 * h, q + 0.5 * h * k1q, k2q)[0]
                    k3q = qd + 0.5 * h * k2v
                    k3v = accel(t + 0.5 * h, q + 0.5 * h * k2q, k3q)[0]
                    k4q = qd + h * k3v
                    k4v = accel(t + h, q + h * k3q, k4q)[0]
                    q = q + h / 6.0 * (k1q + 2 * k2q + 2 * k3q + k4q)
                    qd = qd + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
                elif scheme == "euler":
                    q = q + qd * h + 0.5 * a * h * h
                    qd = qd + a * h
                else:  # semi-implicit (symplectic) Euler
                    qd = qd + a * h
                    q = q + qd * h
                t = (k + 1) * dt if k < steps - 1 else float(duration)
                if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
                    raise SymdynError(
                        f"the simulation diverged at t = {t:.6g} s (the state is no longer finite); "
                        "try a smaller dt or the rk4 integrator"
                    )
                T[k + 1], Q[k + 1], QD[k + 1] = t, q, qd
                bar.update(k + 1, t)
            U[steps] = tau_at(t, q, qd)
    finally:
        bar.close()
    return Trajectory(plant.robot, T, Q, QD, U, scheme)


# --------------------------------------------------------------------------- plots


def _figure(rows: int, width: float = 8.0, height_per_row: float = 2.6):
    """A Matplotlib Figure with the Agg canvas (no pyplot, no global backend change)."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - matplotlib is in the test extras
        raise SymdynError("plots need matplotlib (pip install 'symdyn[plot]')") from exc
    fig = Figure(figsize=(width, height_per_row * rows), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def figure_bytes(fig, fmt: str = "png", dpi: int = 120) -> bytes:
    """A figure rendered to bytes (written by the caller with write_atomic)."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=dpi)
    return buf.getvalue()


def _format_of(path: str | os.PathLike) -> str:
    fmt = Path(path).suffix.lower().lstrip(".") or "png"
    if fmt not in ("png", "pdf", "svg"):
        raise SymdynError(f"{path}: plot format '{fmt}' is not supported (use .png, .pdf or .svg)")
    return fmt


def plot_trajectory(traj: Trajectory, path: str | os.PathLike | None = None) -> bytes:
    """Joint positions and velocities against time; with a reference also the tracking error.

    Returns the image bytes; writes them atomically to `path` when given.
    """
    fmt = _format_of(path) if path is not None else "png"
    if traj.q.ndim != 2:
        raise SymdynError("plots show one trajectory, not a batch")
    tracking = traj.q_ref is not None
    fig = _figure(3 if tracking else 2)
    axes = fig.subplots(3 if tracking else 2, 1, sharex=True)
    colors = [f"C{i % 10}" for i in range(traj.n)]
    for i in range(traj.n):
        axes[0].plot(traj.t, traj.q[:, i], color=colors[i], label=f"q{i + 1}")
        axes[1].plot(traj.t, traj.qd[:, i], color=colors[i], label=f"qd{i + 1}")
        if tracking:
            axes[0].plot(traj.t, traj.q_ref[:, i], "--", color=colors[i], label=f"q{i + 1} reference")
            if traj.qd_ref is not None:
                axes[1].plot(traj.t, traj.qd_ref[:, i], "--", color=colors[i], label=f"qd{i + 1} reference")
            err = np.abs(traj.q_ref[:, i] - traj.q[:, i])
            axes[2].semilogy(
                traj.t, np.maximum(err, 1e-16), color=colors[i], label=f"|q{i + 1}_ref - q{i + 1}|"
            )
    axes[0].set_ylabel("q (rad or m)")
    axes[1].set_ylabel("qd (rad/s or m/s)")
    if tracking:
        axes[2].set_ylabel("tracking error")
        axes[0].set_title(f"{traj.robot.name}: reference (dashed) and actual (solid), {traj.integrator}")
    else:
        axes[0].set_title(f"{traj.robot.name}: simulation ({traj.integrator})")
    axes[-1].set_xlabel("t (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize="small", ncol=2)
    data = figure_bytes(fig, fmt)
    if path is not None:
        write_atomic(path, data)
    return data
