"""The CasADi route: a generic numeric-style RNEA traced in casadi.SX and compiled to C.

This is what urdf2casadi and adam users do instead of symbolic generation: write
the recursive Newton-Euler algorithm once, generically, with 6x6 spatial
(Plucker) matrices over `casadi.SX`, evaluate it on symbolic q, qd, qdd for a
robot with numeric parameters, and hand the resulting expression graph to
CasADi's C code generator. Nothing here is tuned for the benchmark: there is no
per-robot special-casing and no extra common-subexpression pass; CasADi's own
construction-time simplifications (x*0 -> 0, x*1 -> x, x+0 -> x) are all that
removes structural zeros.

Functions (all with numeric parameters; inputs are column vectors of length n):

* ``inverse_dynamics(q, qd, qdd) -> tau``: RNEA with gravity as the fictitious
  base acceleration a_0 = [0; -g], plus the reflected rotor inertia
  gear_ratio^2 J_m qdd_i and joint friction viscous qd_i + coulomb sign(qd_i),
  i.e. the same tau = M qdd + V + G + F as symdyn's NAME_inverse_dynamics
  (friction INCLUDED on both sides; terms whose coefficient is 0 fold away).
* ``mass_matrix(q) -> M``: the composite-rigid-body algorithm (CRBA), both
  triangles filled, reflected rotor inertia on the diagonal, dense n x n.
* ``gravity(q) -> G``: the same RNEA traced with qd = qdd = 0 and no friction.

The robot is read from the same `symdyn.model.robot.Robot` the generated C comes from:
`robot.numeric()` gives SymPy numbers, converted to floats here; joint i moves
by parent_T_i(q_i) = placement @ Rot(axis, q_i) (revolute) or placement @
Trans(axis q_i) (prismatic), as `symdyn.model.robot.Link.joint_transform` defines.
The robot may be a kinematic tree (`Robot.parents`, Featherstone's lambda(i), -1 for
the base, parents before children): the RNEA goes outward from each body's parent and
inward into it, the CRBA adds composite inertias into the parent and fills M only along
each body's path to the base. Mimic joints are handled as symdyn.rnea does: the algorithms
run on the nb bodies at q_b = multiplier q[c] + offset (rates multiplier qd[c]) and
project, tau = S^T tau_b, M = S^T M_b S (S the selection matrix, `Robot.selection()`).

    fns = casadi_functions(robot)              # {"inverse_dynamics": casadi.Function, ...}
    flops(fns["inverse_dynamics"])             # OpCount-like dict of the SX algorithm
    write_c(fns, "cr_puma560", out_dir)        # cr_puma560.c / .h via casadi.CodeGenerator
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import casadi as cs
import numpy as np

__all__ = ["RobotArrays", "robot_arrays", "casadi_functions", "flops", "write_c", "verify"]

FUNCTIONS = ("inverse_dynamics", "mass_matrix", "gravity")


# ----------------------------------------------------------------------------- model


@dataclass(frozen=True)
class RobotArrays:
    """The numeric robot as plain floats (what a URDF parser would hand to the RNEA), per body."""

    revolute: tuple[bool, ...]
    R0: np.ndarray  # (n, 3, 3) placement rotation
    p0: np.ndarray  # (n, 3) placement translation
    axis: np.ndarray  # (n, 3) joint axis in the body frame
    mass: np.ndarray  # (n,)
    com: np.ndarray  # (n, 3) body frame
    inertia: np.ndarray  # (n, 3, 3) about the centre of mass
    viscous: np.ndarray  # (n,)
    coulomb: np.ndarray  # (n,)
    reflected: np.ndarray  # (n,) gear_ratio^2 * rotor inertia
    gravity: np.ndarray  # (3,) base frame
    parent: tuple[int, ...]  # lambda(i): the parent body, -1 for the base
    coordinate: tuple[int, ...]  # the independent coordinate that drives the body's joint
    multiplier: np.ndarray  # (nb,) q_b = multiplier q[coordinate] + offset (1 and 0 unless mimic)
    offset: np.ndarray  # (nb,)

    @property
    def nb(self) -> int:
        """Number of bodies (joints, mimic joints included)."""
        return len(self.revolute)

    @property
    def n(self) -> int:
        """Number of independent coordinates."""
        return max(self.coordinate, default=-1) + 1

    @property
    def has_mimic(self) -> bool:
        return self.n != self.nb


def _f(x) -> np.ndarray:
    return np.array(np.asarray(x).tolist(), dtype=float)


def robot_arrays(robot, params=None) -> RobotArrays:
    """Floats for every quantity of `robot.numeric(params)`."""
    r = robot.numeric(params)
    links = r.links
    coords = r.coordinates
    return RobotArrays(
        revolute=tuple(lk.joint == "revolute" for lk in links),
        R0=np.array([_f(lk.placement.R).reshape(3, 3) for lk in links]),
        p0=np.array([_f(lk.placement.p).reshape(3) for lk in links]),
        axis=np.array([_f(lk.axis).reshape(3) for lk in links]),
        mass=np.array([float(lk.mass) for lk in links]),
        com=np.array([_f(lk.com).reshape(3) for lk in links]),
        inertia=np.array([_f(lk.inertia).reshape(3, 3) for lk in links]),
        viscous=np.array([float(lk.friction.viscous) for lk in links]),
        coulomb=np.array([float(lk.friction.coulomb) for lk in links]),
        reflected=np.array([float(lk.motor.reflected_inertia) for lk in links]),
        gravity=_f(r.gravity).reshape(3),
        parent=tuple(r.parents),
        coordinate=tuple(c.index for c in coords),
        multiplier=np.array([float(c.multiplier) for c in coords]),
        offset=np.array([float(c.offset) for c in coords]),
    )


# ----------------------------------------------------------------------------- spatial algebra (SX)


def skew(v):
    return cs.vertcat(
        cs.horzcat(0, -v[2], v[1]),
        cs.horzcat(v[2], 0, -v[0]),
        cs.horzcat(-v[1], v[0], 0),
    )


def rodrigues(axis: np.ndarray, angle):
    """Rotation by `angle` about the unit `axis`: c I + s [k]x + (1 - c) k k^T."""
    c, s = cs.cos(angle), cs.sin(angle)
    k = cs.DM(axis)
    return c * cs.DM.eye(3) + s * skew(k) + (1 - c) * (k @ k.T)


def motion_transform(E, r):
    """i_X_p for child pose (E, r) in the parent: [[E^T, 0], [-E^T [r]x, E^T]]."""
    Et = E.T
    return cs.vertcat(cs.horzcat(Et, cs.SX.zeros(3, 3)), cs.horzcat(-Et @ skew(r), Et))


def motion_cross(v):
    """v x (motion): [[w x, 0], [v_O x, w x]]."""
    W, V = skew(v[:3]), skew(v[3:])
    return cs.vertcat(cs.horzcat(W, cs.SX.zeros(3, 3)), cs.horzcat(V, W))


def force_cross(v):
    """v x* (force) = -(v x)^T."""
    return -motion_cross(v).T


def spatial_inertia(mass: float, com: np.ndarray, inertia: np.ndarray) -> cs.DM:
    """6x6 spatial inertia about the body origin: [[Ic + m c c^T..., m [c]x], [m [c]x^T, m 1]]."""
    C = np.array([[0, -com[2], com[1]], [com[2], 0, -com[0]], [-com[1], com[0], 0]])
    top = np.hstack([inertia + mass * C @ C.T, mass * C])
    bottom = np.hstack([mass * C.T, mass * np.eye(3)])
    return cs.DM(np.vstack([top, bottom]))


def joint_subspace(revolute: bool, axis: np.ndarray) -> cs.DM:
    s = np.zeros(6)
    if revolute:
        s[:3] = axis
    else:
        s[3:] = axis
    return cs.DM(s)


def _body_values(m: RobotArrays, x, offset: bool) -> list:
    """Per body: multiplier x[c] (+ offset): the bodies' joint positions (offset) or rates."""
    out = []
    for i in range(m.nb):
        xi = x[m.coordinate[i]]
        if m.multiplier[i] != 1.0:
            xi = m.multiplier[i] * xi
        if offset and m.offset[i] != 0.0:
            xi = xi + m.offset[i]
        out.append(xi)
    return out


def _transforms(m: RobotArrays, q):
    """i_X_lambda(i) per body, for the bodies' joint positions q (list of nb)."""
    xs = []
    for i in range(m.nb):
        R0, p0 = cs.DM(m.R0[i]), cs.DM(m.p0[i])
        if m.revolute[i]:
            E, r = R0 @ rodrigues(m.axis[i], q[i]), p0
        else:
            E, r = R0, p0 + q[i] * (R0 @ cs.DM(m.axis[i]))
        xs.append(motion_transform(E, r))
    return xs


# ----------------------------------------------------------------------------- algorithms (SX)


def rnea(m: RobotArrays, q, qd, qdd, gravity: bool = True, friction: bool = True):
    """Featherstone's RNEA over SX on the tree: tau (n x 1), body frames, p = lambda(i).

    Outward: v_i = X_i v_p + S_i qd_i, a_i = X_i a_p + S_i qdd_i + v_i x S_i qd_i (v_p = 0,
    a_p = [0; -g] for the base), f_i = I_i a_i + v_i x* I_i v_i. Inward: tau_i = S_i^T f_i,
    f_p += X_i^T f_i. Per body at q_b, qd_b, qdd_b, then tau = S^T tau_b.
    """
    q, qd, qdd = _body_values(m, q, True), _body_values(m, qd, False), _body_values(m, qdd, False)
    X = _transforms(m, q)
    S = [joint_subspace(m.revolute[i], m.axis[i]) for i in range(m.nb)]
    Ii = [spatial_inertia(m.mass[i], m.com[i], m.inertia[i]) for i in range(m.nb)]
    base_v = cs.SX.zeros(6, 1)
    base_a = cs.vertcat(cs.SX.zeros(3, 1), -cs.DM(m.gravity)) if gravity else cs.SX.zeros(6, 1)
    v, a, f = [], [], []
    for i in range(m.nb):
        p = m.parent[i]
        v_p, a_p = (base_v, base_a) if p < 0 else (v[p], a[p])
        v.append(X[i] @ v_p + S[i] * qd[i])
        a.append(X[i] @ a_p + S[i] * qdd[i] + motion_cross(v[i]) @ S[i] * qd[i])
        f.append(Ii[i] @ a[i] + force_cross(v[i]) @ (Ii[i] @ v[i]))
    tau = [None] * m.nb
    for i in reversed(range(m.nb)):  # children come after their parent: f[i] is complete
        tau[i] = S[i].T @ f[i] + m.reflected[i] * qdd[i]
        if friction:
            tau[i] += m.viscous[i] * qd[i] + m.coulomb[i] * cs.sign(qd[i])
        if m.parent[i] >= 0:
            f[m.parent[i]] = f[m.parent[i]] + X[i].T @ f[i]
    if not m.has_mimic:
        return cs.vertcat(*tau)
    out = [cs.SX(0)] * m.n  # S^T tau_b
    for i in range(m.nb):
        out[m.coordinate[i]] = out[m.coordinate[i]] + m.multiplier[i] * tau[i]
    return cs.vertcat(*out)


def crba(m: RobotArrays, q):
    """The composite-rigid-body algorithm over SX on the tree: dense M (n x n), both triangles.

    Ic_p += X_i^T Ic_i X_i (inward); F = Ic_i S_i, M_ii = S_i^T F, and for each ancestor j of
    i, M_ij = M_ji = S_j^T F with F carried down the path, F <- X_k^T F; entries of joints on
    different branches stay zero. With mimic joints this is M_b and M = S^T M_b S.
    """
    X = _transforms(m, _body_values(m, q, True))
    S = [joint_subspace(m.revolute[i], m.axis[i]) for i in range(m.nb)]
    Ic = [cs.SX(spatial_inertia(m.mass[i], m.com[i], m.inertia[i])) for i in range(m.nb)]
    M = cs.SX.zeros(m.nb, m.nb)
    for i in reversed(range(m.nb)):  # Ic[i] is complete: its children come after it
        if m.parent[i] >= 0:
            Ic[m.parent[i]] = Ic[m.parent[i]] + X[i].T @ Ic[i] @ X[i]
        F = Ic[i] @ S[i]
        M[i, i] = S[i].T @ F + m.reflected[i]
        j = i
        while m.parent[j] >= 0:
            F = X[j].T @ F
            j = m.parent[j]
            M[i, j] = S[j].T @ F
            M[j, i] = M[i, j]
    if not m.has_mimic:
        return M
    sel = np.zeros((m.nb, m.n))
    sel[np.arange(m.nb), m.coordinate] = m.multiplier
    return cs.DM(sel).T @ M @ cs.DM(sel)


def casadi_functions(robot, params=None, prefix: str = "cr") -> dict[str, cs.Function]:
    """The traced SX functions {inverse_dynamics, mass_matrix, gravity} of `robot`."""
    m = robot_arrays(robot, params)
    n = m.n
    q, qd, qdd = cs.SX.sym("q", n), cs.SX.sym("qd", n), cs.SX.sym("qdd", n)
    name = f"{prefix}_{robot.name}"
    zero = cs.SX.zeros(n, 1)
    return {
        "inverse_dynamics": cs.Function(
            f"{name}_inverse_dynamics", [q, qd, qdd], [rnea(m, q, qd, qdd)], ["q", "qd", "qdd"], ["tau"]
        ),
        "mass_matrix": cs.Function(f"{name}_mass_matrix", [q], [cs.densify(crba(m, q))], ["q"], ["M"]),
        "gravity": cs.Function(
            f"{name}_gravity", [q], [cs.densify(rnea(m, q, zero, zero, friction=False))], ["q"], ["G"]
        ),
    }


# ----------------------------------------------------------------------------- counting, C, checks

_ADD = {cs.OP_ADD, cs.OP_SUB, cs.OP_TWICE}
_MUL = {cs.OP_MUL, cs.OP_SQ}
_DIV = {cs.OP_DIV, cs.OP_INV}
_TRIG = {cs.OP_SIN, cs.OP_COS, cs.OP_TAN}
_FREE = {cs.OP_INPUT, cs.OP_OUTPUT, cs.OP_CONST, cs.OP_PARAMETER, cs.OP_ASSIGN}


def flops(f: cs.Function) -> dict[str, int]:
    """Operations of an SX function's algorithm, counted as symdyn counts (OpCount).

    add: OP_ADD/SUB/TWICE; mul: OP_MUL/SQ; div: OP_DIV/INV; trig: sin/cos/tan;
    other: every other non-trivial operation except negation (sign, sqrt, ...).
    Negations (OP_NEG) are listed apart and, like symdyn's unary minus, not in
    `total`; inputs, outputs, constants and assignments are free.
    """
    counts = dict(mul=0, add=0, div=0, trig=0, other=0, neg=0)
    for k in range(f.n_instructions()):
        op = f.instruction_id(k)
        if op in _FREE:
            continue
        if op in _ADD:
            counts["add"] += 1
        elif op in _MUL:
            counts["mul"] += 1
        elif op in _DIV:
            counts["div"] += 1
        elif op in _TRIG:
            counts["trig"] += 1
        elif op == cs.OP_NEG:
            counts["neg"] += 1
        else:
            counts["other"] += 1
    counts["total"] = sum(counts[k] for k in ("mul", "add", "div", "trig", "other"))
    counts["instructions"] = f.n_instructions()
    return counts


def write_c(fns: dict[str, cs.Function], basename: str, out_dir) -> tuple[Path, Path]:
    """basename.c and basename.h from casadi.CodeGenerator (one C file, all functions)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cg = cs.CodeGenerator(f"{basename}.c", {"with_header": True})
    for f in fns.values():
        cg.add(f)
    cg.generate(str(out) + "/")
    return out / f"{basename}.c", out / f"{basename}.h"


def verify(robot, fns: dict[str, cs.Function], states: int = 5, seed: int = 7, params=None) -> float:
    """Largest relative error of the CasADi functions against symdyn.rnea at random states."""
    from symdyn import rnea as oracle

    n = robot.n
    rng = np.random.default_rng(seed)
    worst = 0.0
    for _ in range(states):
        q, qd, qdd = (rng.uniform(-1, 1, n) for _ in range(3))
        pairs = [
            (fns["inverse_dynamics"](q, qd, qdd), oracle.rnea(robot, q, qd, qdd, params)),
            (fns["mass_matrix"](q), oracle.mass_matrix(robot, q, params)),
            (fns["gravity"](q), oracle.gravity_torque(robot, q, params)),
        ]
        for got, want in pairs:
            got = np.asarray(cs.DM(got)).reshape(np.shape(want))
            err = np.max(np.abs(got - want)) / max(1.0, np.max(np.abs(want)))
            worst = max(worst, float(err))
    return worst
