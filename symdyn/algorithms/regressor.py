"""The regressor Y(q, qd, qdd) with tau = Y pi, derived symbolically from the Newton-Euler recursion.

The joint efforts are linear in the standard parameters pi (symdyn.model.parameters: per body i
pi_i = m, h = m c, I_O (the tensor about body frame i's origin), then Ia, fv, fc). In body frame i,
with the outward recursion's w_i, wd_i, vd_i (the acceleration of frame i's origin, gravity entered
as a base acceleration) and W_i = [wd_i x] + [w_i x]^2 (symdyn.algorithms.newton_euler), the wrench
about the origin of frame i that accelerates body i is

    F_i = m vd_i + W_i h,    N_i = I_O wd_i + w_i x I_O w_i + h x vd_i,

linear in (m, h, I_O). Joint j's effort collects the wrenches of the bodies i it supports,
tau_j = sum_i s_ji . (N_i, F_i), where s_ji = (s_w, s_v) is joint j's unit motion (a_j, 0) for
a revolute or (0, a_j) for a prismatic joint carried out to frame i (the power product is
frame-invariant; Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 2.9 and 5.3). Carrying
a motion from a parent frame into child frame c (origin p_c, orientation R_c in the parent) is

    s_w' = R_c^T s_w,    s_v' = R_c^T (s_v + s_w x p_c),

and the columns of row j for body i are, with u = s_w x w_i,

    m:      s_v . vd_i
    h:      W_i^T s_v + vd_i x s_w
    I_ab:   s_w,a wd_b + s_w,b wd_a + u_a w_b + u_b w_a  (a != b),   I_aa: s_w,a wd_a + u_a w_a

(Atkeson, An and Hollerbach, "Estimation of inertial parameters of manipulator loads and links",
1986; Khalil and Dombre, Modeling, Identification and Control of Robots (2002), ch. 9). The joint's
own columns are qdd_j (rotor), qd_j (viscous) and sign(qd_j) (Coulomb) on its row; with
direction-dependent Coulomb friction H(qd_j) (c+) there and -H(-qd_j) (c-) in the column of fcn_j,
after the 13 nb others (symdyn.model.parameters; H(0) = 0). Only one motion
vector per pair (j, i) is carried, never the ten wrench columns, and exact zeros fold away, so a
chain costs O(n^2) small products. Mimic joints: the recursion runs on the nb bodies at q_b, S qd,
S qdd and the rows are projected, Y = S^T Y_b (symdyn.algorithms.coordinates), so Y is n x 13 nb
(plus one column per link with direction-dependent Coulomb friction).

Floating base (`floating_regressor`): the recursion starts from the moving base, and six base rows
(force, then moment about the base origin, base frame) come first: row k is the power of the
base's unit motion e_k carried out to every body, so every body's 10 inertial columns enter them,
and the base body's own 10 (m0 ... Izz0, the last columns) enter them alone.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.parameters import PER_BODY, asymmetric_bodies
from ..model.robot import Robot
from ..spatial import vectors as v3
from ..spatial.motion import Motion, motion_subspace
from ..symbolic.program import Program
from .coordinates import project_vector
from .floating import base_gravity_vector
from .frames import JointFrame, joint_frames
from .newton_euler import LinkAcceleration, outward, tilde

__all__ = ["regressor", "body_regressor", "floating_regressor"]

#: the entries (a, b) of I_O in Pinocchio's toDynamicParameters order: xx, xy, yy, xz, yz, zz
_I_ENTRIES = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))


def _inertial_columns(s: Motion, motion: LinkAcceleration, W: v3.Mat) -> list[sp.Expr]:
    """s . (N, F) per inertial parameter of a body (m, h_x, h_y, h_z, I_xx ... I_zz), body frame."""
    sw, sv = s
    w, wd, vd = motion
    Wt_sv = tuple(v3.sum_terms(v3.product(W[r][k], sv[r]) for r in range(3)) for k in range(3))
    h = v3.add(Wt_sv, v3.cross(vd, sw))
    u = v3.cross(sw, w)
    inertia = []
    for a, b in _I_ENTRIES:
        pairs = ((sw[a], wd[a]), (u[a], w[a])) if a == b else ((sw[a], wd[b]), (sw[b], wd[a]), (u[a], w[b]))
        terms = [v3.product(x, y) for x, y in pairs]
        if a != b:
            terms.append(v3.product(u[b], w[a]))
        inertia.append(v3.sum_terms(terms))
    return [v3.dot(sv, vd), *h, *inertia]


def _to_child(frame: JointFrame, s: Motion, program: Program, hint: str) -> Motion:
    """A motion of the parent frame carried into the child frame: (R^T s_w, R^T (s_v + s_w x p))."""
    sw, sv = s
    return Motion(
        program.let_vector(v3.mul_t(frame.R, sw), hint),
        program.let_vector(v3.mul_t(frame.R, v3.add(sv, v3.cross(sw, frame.p))), hint),
    )


def _motions(
    robot: Robot,
    frames: list[JointFrame],
    base: LinkAcceleration,
    W_base: v3.Mat,
    qd_b,
    qdd_b,
    program: Program,
):
    """The outward recursion's (w, wd, vd) and W of every body, from the base's motion and W."""
    motions: list[LinkAcceleration] = []
    Ws: list[v3.Mat] = []
    for i, link in enumerate(robot.links):
        k = f"T{i + 1}"
        p = robot.parents[i]
        parent, W_parent = (base, W_base) if p < 0 else (motions[p], Ws[p])
        motions.append(outward(link, frames[i], parent, W_parent, qd_b[i], qdd_b[i], program, k))
        Ws.append(tilde(program, motions[i].w, motions[i].wd, k))
    return motions, Ws


def body_regressor(
    robot: Robot,
    q_b: Sequence,
    qd_b: Sequence,
    qdd_b: Sequence,
    program: Program,
    rotations: list[JointFrame] | None = None,
    base: LinkAcceleration | None = None,
    base_rows: list[list[sp.Expr]] | None = None,
) -> list[list[sp.Expr]]:
    """Y_b (nb x 13 nb, + fcn columns) with tau_b = Y_b pi: the bodies' joint efforts, rotor and
    friction included.

    Args:
        robot: the model, nb bodies in a tree (parents first).
        q_b, qd_b, qdd_b: nb joint positions, rates and accelerations of the bodies.
        program: receives the named intermediates (the outward recursion's and the entries).
        rotations: `joint_frames(robot, q_b)`, to share them.
        base: the base's (w, wd, vd) in the base frame (a floating base: `floating_regressor`);
            None for a fixed base, (0, 0, -g).
        base_rows: receives a floating base's six rows (`_base_rows`), when given.

    Returns:
        nb rows of 13 nb expressions over the program's intermediates (body joint space).
    """
    nb = robot.nb
    parents = robot.parents
    frames = rotations if rotations is not None else joint_frames(robot, q_b)
    if base is None:
        base = LinkAcceleration(
            v3.ZERO3, v3.ZERO3, program.let_vector(v3.neg(v3.vec(robot.base_gravity)), "Tg")
        )
        W_base = v3.ZERO33
    else:
        W_base = tilde(program, base.w, base.wd, "Tb")
    motions, Ws = _motions(robot, frames, base, W_base, qd_b, qdd_b, program)
    extra = {i: PER_BODY * nb + k for k, i in enumerate(asymmetric_bodies(robot))}
    width = PER_BODY * nb + len(extra)
    Y: list[list[sp.Expr]] = [[sp.S.Zero] * width for _ in range(nb)]
    for j, link in enumerate(robot.links):
        carried = {j: motion_subspace(link.joint, link.axis)}  # joint j's unit motion, frame i
        Y[j][PER_BODY * j : PER_BODY * j + 10] = _row_columns(
            carried[j], motions[j], Ws[j], program, f"Y{j + 1}_"
        )
        for i in range(j + 1, nb):
            if parents[i] not in carried:
                continue  # not in joint j's subtree
            carried[i] = _to_child(frames[i], carried[parents[i]], program, f"s{j + 1}_{i + 1}_")
            Y[j][PER_BODY * i : PER_BODY * i + 10] = _row_columns(
                carried[i], motions[i], Ws[i], program, f"Y{j + 1}_"
            )
        coulomb = link.friction.coulomb_columns(qd_b[j])
        Y[j][PER_BODY * j + 10 : PER_BODY * j + 13] = [sp.sympify(qdd_b[j]), qd_b[j], coulomb[0]]
        if j in extra:
            Y[j][extra[j]] = coulomb[1]
    if base_rows is not None:
        base_rows.extend(_base_rows(robot, frames, (motions, Ws), (base, W_base), width, program))
    return Y


def _row_columns(
    s: Motion, motion: LinkAcceleration, W: v3.Mat, program: Program, hint: str
) -> list[sp.Expr]:
    """The 10 inertial columns of one body in the row of the unit motion s, named."""
    return [program.let(c, hint) for c in _inertial_columns(s, motion, W)]


def _base_rows(robot: Robot, frames: list[JointFrame], bodies, base, width: int, program: Program):
    """The six base rows of a floating robot (force along x, y, z, then moment about x, y, z; base
    frame): row k is the power of the base's unit motion e_k (a translation, then a rotation about
    the base origin) carried out to every body, so every body's 10 inertial columns enter, and
    the base body's own 10 columns last (width + 10 columns in all). bodies: the bodies' motions
    and W; base: the base's motion and W."""
    motions, Ws = bodies
    rows = []
    for k in range(6):
        e = tuple(sp.S.One if r == k % 3 else sp.S.Zero for r in range(3))
        s = Motion(v3.ZERO3, e) if k < 3 else Motion(e, v3.ZERO3)
        row = [sp.S.Zero] * (width + 10)
        carried: dict[int, Motion] = {-1: s}
        for i in range(robot.nb):
            carried[i] = _to_child(frames[i], carried[robot.parents[i]], program, f"s0{k + 1}_{i + 1}_")
            row[PER_BODY * i : PER_BODY * i + 10] = _row_columns(
                carried[i], motions[i], Ws[i], program, "Y0_"
            )
        row[width:] = _row_columns(s, *base, program, "Y0_")
        rows.append(row)
    return rows


def regressor(robot: Robot, q: Sequence, qd: Sequence, qdd: Sequence, program: Program) -> sp.Matrix:
    """The regressor Y(q, qd, qdd), n x 13 nb (+ fcn columns), with tau = Y pi (joint space; see
    the module docstring); on a floating base NV x (13 nb + fcn columns + 10), the six base rows
    first and the base body's 10 columns last (`floating_regressor`).

    Args:
        robot: the model (parameters with values substituted: `Robot.resolved`).
        q, qd, qdd: n symbols each, the independent coordinates (NQ, NV, NV on a floating base).
        program: receives the named intermediates.

    Returns:
        Y over the program's intermediates; column 13 i + k is parameter k of body i + 1 in the order
        of `symdyn.standard_parameters`.
    """
    if robot.floating:
        return floating_regressor(robot, q, qd, qdd, program)
    q_b, qd_b, qdd_b = robot.body_positions(list(q)), robot.body_rates(list(qd)), robot.body_rates(list(qdd))
    Y_b = body_regressor(robot, q_b, qd_b, qdd_b, program)
    columns = [project_vector(robot, [row[c] for row in Y_b], program, "Y") for c in range(len(Y_b[0]))]
    return sp.Matrix(robot.n, len(columns), lambda r, c: columns[c][r])


def floating_regressor(robot: Robot, q: Sequence, qd: Sequence, qdd: Sequence, program: Program) -> sp.Matrix:
    """Y (NV x (13 nb + fcn columns + 10)) of a floating robot, tau = Y pi with pi of
    `symdyn.standard_parameters` (the base body's m0 ... Izz0 last).

    The recursion runs from the moving base, w_0 = w, wd_0 = dw, vd_0 = a + w x v - R^T g
    (symdyn.algorithms.floating); the joint rows are the fixed base's, and the six base rows
    (force, then moment about the base origin, base frame) hold every body's inertial columns:
    the wrench on the base is the sum of all the bodies' wrenches carried down to it, base body
    included. Rotor and friction columns are zero in the base rows; the base body's columns are
    zero in the joint rows.
    """
    q, qd, qdd = list(q), list(qd), list(qdd)
    q_b, qd_b, qdd_b = robot.body_positions(q[7:]), robot.body_rates(qd[6:]), robot.body_rates(qdd[6:])
    g_b = base_gravity_vector(robot, q[3:7], program)
    w, lin = v3.vec(qd[3:6]), v3.vec(qd[:3])
    vd = program.let_vector(v3.sub(v3.add(v3.vec(qdd[:3]), v3.cross(w, lin)), g_b), "Tvd0_")
    base = LinkAcceleration(w, v3.vec(qdd[3:6]), vd)
    rows: list[list[sp.Expr]] = []
    Y_b = body_regressor(robot, q_b, qd_b, qdd_b, program, base=base, base_rows=rows)
    width = len(rows[0]) - 10  # (Y_b has no rows on a single rigid body)
    columns = [project_vector(robot, [row[c] for row in Y_b], program, "Y") for c in range(width)]
    return sp.Matrix(
        robot.n + 6, width + 10, lambda r, c: rows[r][c] if r < 6 else (columns[c][r - 6] if c < width else 0)
    )
