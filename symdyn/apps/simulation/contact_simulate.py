"""Simulation of a robot in contact with the world (docs/contacts.md, "Simulating contacts").

The robot's contacts (Robot.contacts) that hold are kept by the constrained forward dynamics of
the generated C (symdyn.compile's contact_forward_dynamics):

    M qdd + b + F = tau + Jc^T lambda,   Jc qdd + gamma = -Kd Jc qd - Kp e(q)   (held rows)

with Baumgarte's stabilisation on the right (velocity gain Kd in 1/s, position gain Kp in 1/s^2,
default 0: the exact constraint Jc qdd + gamma = 0). e(q) is each held contact's position error
against its anchor, the pose of its frame when the contact began to hold
(symdyn.algorithms.contact_error). With a gain not zero the generated
contact_forward_dynamics_baumgarte solves the stabilised system (the plant needs the group
contact_baumgarte); with both zero, contact_forward_dynamics the exact one.

The stance may change (`stance`, symdyn.apps.simulation.stance): at the first sample t_k >= T of
each change, the contacts that start to hold get the generated impulse_dynamics (the new stance
held, restitution e, default 0: they stop) and are anchored where they are; the contacts that stop
holding are released. A touchdown `impulse_at` T is the stance "free, then every contact from T".
The configuration is integrated as in symdyn.apps.simulation.floating_stepping (its schemes, on
SE(3) x R^n for a floating base; q + h qd on a fixed one). The stepping loop runs in Python
around the compiled C functions (one call of the constrained dynamics per stage, a few
microseconds each): the loop of symdyn.apps.simulation.stepping in C does not handle the mask,
the anchors and the impulses. The contact forces at every sample are those of the constrained
dynamics there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import SymdynError
from ...model.quaternion_norm import check_quaternions, quaternion_norms
from .floating_stepping import FLOATING_SCHEMES, floating_sizes, run_floating
from .stance import stance_schedule
from .stepping import sample_times, torque_rows
from .trajectory import Trajectory

__all__ = [
    "ContactTrajectory",
    "simulate_contacts",
    "joint_pd",
    "contact_columns",
    "plot_contact_forces",
    "DAMPING",
]

#: the damping mu of the generated KKT solve (symdyn.algorithms.contact_dynamics.DAMPING), spelled
#: here so that a cached robot's results can be checked without SymPy; tests/test_contact_simulate.py
#: checks it
DAMPING = 1e-10
_AXES = ("fx", "fy", "fz", "mx", "my", "mz")


def contact_columns(contacts) -> list[str]:
    """The CSV columns of the contact forces: <name>_fx, _fy, _fz (and _mx, _my, _mz of a 6d one)."""
    return [f"{c.name}_{a}" for c in contacts for a in _AXES[: c.rows]]


@dataclass
class ContactTrajectory(Trajectory):
    """A Trajectory in contact: `lam` (N, NLAMBDA) the contact forces in the rows' axes (a point's
    world-aligned force, a 6d frame's force and moment in its own axes), `active` (N, NCONTACT) the
    mask at each sample, `impulse` (NLAMBDA,) the first touchdown's (None without one) at
    `impulse_time`, where qd jumped from `qd_before` to qd[k], `touchdowns` every touchdown as
    (time, impulse, qd_before), `poses` (N, NCONTACT, 4, 4) the contact frames' world poses."""

    lam: np.ndarray | None = None
    active: np.ndarray | None = None
    impulse: np.ndarray | None = None
    impulse_time: float | None = None
    poses: np.ndarray | None = None
    qd_before: np.ndarray | None = None
    touchdowns: tuple = ()

    @property
    def contact_forces(self) -> np.ndarray:
        """(N, NCONTACT, 3): each contact's force on the robot in world axes (a 6d one's rotated)."""
        out, row = np.empty((len(self.t), len(self.robot.contacts), 3)), 0
        for j, c in enumerate(self.robot.contacts):
            f = self.lam[:, row : row + 3]
            out[:, j] = f if c.kind == "point" else np.einsum("nij,nj->ni", self.poses[:, j, :3, :3], f)
            row += c.rows
        return out

    def contact_positions(self) -> np.ndarray:
        """(N, NCONTACT, 3): the contact frames' origins in the world."""
        return self.poses[:, :, :3, 3]

    def _columns(self) -> tuple[list[str], np.ndarray]:
        header, values = super()._columns()
        return header + contact_columns(self.robot.contacts), np.column_stack([values, self.lam])


def joint_pd(q_hold, kp: float, kd: float, nv: int):
    """tau(t, q, v) of a joint PD controller holding the joints at q_hold's: tau_j = kp (q_hold_j - q_j)
    - kd v_j on the joints, 0 on a floating base's six rows."""
    q_hold = np.asarray(q_hold, dtype=float)
    n = nv if len(q_hold) == nv else nv - 6  # the joints: a floating base (NQ = NV + 1) has 6 rows more
    held = q_hold[len(q_hold) - n :]

    def tau(t, q, v):
        out = np.zeros(nv)
        out[nv - n :] = kp * (held - q[len(q) - n :]) - kd * v[nv - n :]
        return out

    return tau


def _check_number(value, name: str, low: float = 0.0, high: float = math.inf) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)):
        raise SymdynError(f"{name} must be a number, got {type(value).__name__}")
    if not (low <= float(value) <= high):  # also NaN
        raise SymdynError(f"{name} must be a number in [{low:g}, {high:g}], got {value!r}")
    return float(value)


class _Geometry:
    """The contact frames' world poses at q (symdyn.algorithms.drawing's numeric kinematics)."""

    def __init__(self, robot, params) -> None:
        from ...algorithms.drawing import scene_function

        self.scene = scene_function(robot, params)
        self.names = [c.name for c in robot.contacts]

    def poses(self, q) -> np.ndarray:
        frames = {f.name: f for f in self.scene(q).frames if f.kind == "contact"}
        out = np.zeros((len(self.names), 4, 4))
        for j, name in enumerate(self.names):
            out[j, :3, :3], out[j, :3, 3], out[j, 3, 3] = frames[name].axes, frames[name].origin, 1.0
        return out


def anchor_numbers(poses: np.ndarray) -> np.ndarray:
    """The generated functions' anchor (NCONTACT * 12) of the poses (NCONTACT, 4, 4): per contact
    its origin, then its rotation row-major."""
    return np.concatenate([np.r_[T[:3, 3], T[:3, :3].reshape(-1)] for T in poses])


class _FixedBase:
    """A fixed-base plant seen by floating_stepping.run_floating: integrate(q, xi) = q + xi."""

    def __init__(self, plant) -> None:
        self.robot, self.functions = plant.robot, ("integrate",)

    @staticmethod
    def integrate(q, xi, scale):
        return q + xi * scale[0]


def simulate_contacts(
    plant,
    robot,
    q0,
    qd0=None,
    duration: float = 1.0,
    dt: float = 1e-3,
    tau=None,
    integrator: str = "semi-implicit",
    impulse_at: float | None = None,
    restitution: float = 0.0,
    baumgarte: tuple[float, float] = (0.0, 0.0),
    params=None,
    stance=None,
) -> ContactTrajectory:
    """Integrate the constrained dynamics of `plant` (symdyn.compile of `robot`, a Robot with
    contacts, its group `contacts` built) from (q0, qd0) over [0, duration] with step dt.

    tau: None, NV numbers or expressions of t, or a callable tau(t, q, qd) -> (NV,) (joint_pd).
    impulse_at: the touchdown time in (0, duration] (None: the contacts hold from t = 0);
    stance: [(T, contact names), ...], the contacts that hold from T on (symdyn.apps.simulation.
    stance; not with impulse_at); restitution in [0, 1], of every touchdown; baumgarte: (Kp, Kd)
    >= 0, a gain not zero needs the plant's group contact_baumgarte. Raises SymdynError for bad
    input and when the state stops being finite.
    """
    from .simulate import initial_state, torque_function, torque_table

    if not robot.contacts:
        raise SymdynError(f"robot '{robot.name}' has no contacts (give --contacts FRAME ...)")
    missing = [f for f in ("contact_forward_dynamics", "impulse_dynamics") if f not in plant.functions]
    if missing:
        raise SymdynError(f"robot '{robot.name}': no {missing[0]} function (M(q) singular?), cannot simulate")
    if integrator not in (*FLOATING_SCHEMES, "lecture"):
        raise SymdynError(
            f"integrator '{integrator}' does not apply with contacts (one of {', '.join(FLOATING_SCHEMES)})"
        )
    for name, v in (("duration", duration), ("dt", dt)):
        _check_number(v, name)
        if not v > 0 or not math.isfinite(v):
            raise SymdynError(f"{name} must be a positive number, got {v!r}")
    if dt > duration:
        raise SymdynError(f"dt ({dt}) is longer than the duration ({duration})")
    if duration / dt > 10_000_000:
        raise SymdynError(f"duration {duration:g} s with dt {dt:g} s is too many steps; increase dt")
    if impulse_at is not None:
        _check_number(impulse_at, "the impulse time")
        if not 0.0 < impulse_at <= duration:
            raise SymdynError(
                f"the impulse time {impulse_at!r} s must lie in (0, {duration:g}] s, the run's time"
            )
    e = _check_number(restitution, "the restitution", 0.0, 1.0)
    kp, kd = (
        _check_number(g, name)
        for g, name in zip(baumgarte, ("Baumgarte's Kp", "Baumgarte's Kd"), strict=True)
    )
    stabilised = kp != 0.0 or kd != 0.0
    if stabilised and "contact_forward_dynamics_baumgarte" not in plant.functions:
        raise SymdynError(
            f"robot '{robot.name}': Baumgarte's gains need contact_forward_dynamics_baumgarte (compile "
            "with the group contact_baumgarte)"
        )
    sizes = floating_sizes(plant)
    nq, nv = sizes if sizes is not None else (robot.n, robot.n)
    q = initial_state(q0, nq, "q0")
    v = np.zeros(nv) if qd0 is None else initial_state(qd0, nv, "qd0")
    if q.ndim != 1 or v.ndim != 1:
        raise SymdynError("a simulation with contacts starts from one state")
    if sizes is not None:
        check_quaternions(q, "q0")
        q[3:7] /= quaternion_norms(q)
    t, h = sample_times(duration, dt)
    schedule = stance_schedule(robot, t, duration, stance, impulse_at)
    table = torque_table(tau, nv, torque_rows(t, h))
    torque = torque_function(tau, nv) if table is None else None
    geometry = _Geometry(robot, params)
    ncontact = len(robot.contacts)
    scheme = "euler" if integrator == "lecture" else integrator
    stepper = plant if sizes is not None else _FixedBase(plant)
    gains = (kp, kd) if stabilised else None
    Q, V, U = np.empty((len(t), nq)), np.empty((len(t), nv)), np.empty((len(t), nv))
    active_rows, anchored = np.zeros((len(t), ncontact)), np.empty((len(t), ncontact, 12))
    touchdowns, held, anchors = [], np.zeros(ncontact), anchor_numbers(geometry.poses(q))
    ends = [k for k, _ in schedule[1:]] + [len(h)]
    for (first, active), last in zip(schedule, ends, strict=True):
        new = (active > 0) & ~(held > 0)
        if first > 0 and new.any():
            before = v
            v, impulse = plant.impulse_dynamics(q, v, active, np.array([e]))
            touchdowns.append((float(t[first]), impulse, before))
        if new.any():  # the contacts that start to hold are anchored where they are
            fresh = anchor_numbers(geometry.poses(q)).reshape(ncontact, 12)
            anchors = np.where(new[:, None], fresh, anchors.reshape(ncontact, 12)).reshape(-1)
        held = active
        accel = _constrained(plant, active, anchors, gains)
        offset = 3 * first

        def tau_at(row, tk, qk, vk, offset=offset):
            if table is not None:
                return table[offset + row]
            return np.broadcast_to(np.asarray(torque(tk, qk, vk), dtype=float), vk.shape)

        if last > first:
            Qs, Vs, Us = run_floating(
                stepper, scheme, q, v, h[first:last], t[first : last + 1], tau_at, accel, sizes is None
            )
            Q[first : last + 1], V[first : last + 1], U[first:last] = Qs, Vs, Us[:-1]
            q, v = Qs[-1], Vs[-1]
        else:
            Q[first], V[first] = q, v
        active_rows[first : last + 1], anchored[first : last + 1] = active, anchors.reshape(ncontact, 12)
        U[last] = tau_at(3 * (last - first), t[last], q, v)
    poses = np.array([geometry.poses(x) for x in Q])
    lam = np.empty((len(t), sum(c.rows for c in robot.contacts)))
    A = np.empty((len(t), nv))
    for k in range(len(t)):
        accel = _constrained(plant, active_rows[k], anchored[k].reshape(-1), gains)
        A[k], lam[k] = accel(Q[k], V[k], U[k], forces=True)
    first = touchdowns[0] if touchdowns else (None, None, None)
    return ContactTrajectory(
        robot,
        t,
        Q,
        V,
        U,
        scheme,
        plant=plant,
        qdd=A,
        lam=lam,
        active=active_rows,
        impulse=first[1],
        impulse_time=first[0],
        poses=poses,
        qd_before=first[2],
        touchdowns=tuple(touchdowns),
    )


def _constrained(plant, active: np.ndarray, anchors: np.ndarray, gains: tuple[float, float] | None):
    """accel(q, v, tau, forces=False) -> qdd (and lambda): the generated constrained dynamics, with
    Baumgarte's term (the module docstring) when `gains` (Kp, Kd) are given."""
    if gains is None:
        fd = plant.contact_forward_dynamics

        def solve(q, v, tau):
            return fd(q, v, tau, active)
    else:
        fd, k = plant.contact_forward_dynamics_baumgarte, np.array(gains, dtype=float)

        def solve(q, v, tau):
            return fd(q, v, tau, active, anchors, k)

    def accel(q, v, tau, forces: bool = False):
        qdd, lam = solve(q, v, tau)
        return (qdd, lam) if forces else qdd

    return accel


def plot_contact_forces(traj: ContactTrajectory, path=None) -> bytes:
    """The contact forces against time (world axes, N; a 6d contact's force, its moment left out),
    one panel per axis, with the total beside the weight's share; the image bytes, written
    atomically to `path` when given."""
    from ..output import figure, figure_bytes, plot_format, write_atomic

    fmt = plot_format(path) if path is not None else "png"
    F = traj.contact_forces
    fig = figure(3)
    axes = fig.subplots(3, 1, sharex=True)
    for i, (ax, name) in enumerate(zip(axes, "xyz", strict=True)):
        for j, c in enumerate(traj.robot.contacts):
            ax.plot(traj.t, F[:, j, i], color=f"C{j % 10}", label=c.name)
        ax.plot(traj.t, F[:, :, i].sum(axis=1), "k--", label="sum")
        ax.set_ylabel(f"f{name} (N)")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="upper right", fontsize="small", ncol=3)
    changes = np.flatnonzero(np.any(np.diff(traj.active, axis=0) != 0, axis=1)) + 1  # the stance's
    for k in changes:
        for ax in axes:
            ax.axvline(traj.t[k], color="0.5", lw=0.8)
    axes[0].set_title(f"{traj.robot.name}: contact forces on the robot, world axes ({traj.integrator})")
    axes[-1].set_xlabel("t (s)")
    data = figure_bytes(fig, fmt)
    if path is not None:
        write_atomic(path, data)
    return data
