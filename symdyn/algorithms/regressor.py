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
from .frames import JointFrame, joint_frames
from .newton_euler import LinkAcceleration, outward, tilde

__all__ = ["regressor", "body_regressor"]

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


def body_regressor(
    robot: Robot,
    q_b: Sequence,
    qd_b: Sequence,
    qdd_b: Sequence,
    program: Program,
    rotations: list[JointFrame] | None = None,
) -> list[list[sp.Expr]]:
    """Y_b (nb x 13 nb, + fcn columns) with tau_b = Y_b pi: the bodies' joint efforts, rotor and
    friction included.

    Args:
        robot: the model, nb bodies in a tree (parents first).
        q_b, qd_b, qdd_b: nb joint positions, rates and accelerations of the bodies.
        program: receives the named intermediates (the outward recursion's and the entries).
        rotations: `joint_frames(robot, q_b)`, to share them.

    Returns:
        nb rows of 13 nb expressions over the program's intermediates (body joint space).
    """
    nb = robot.nb
    parents = robot.parents
    frames = rotations if rotations is not None else joint_frames(robot, q_b)
    vd_0 = program.let_vector(v3.neg(v3.vec(robot.base_gravity)), "Tg")
    base = LinkAcceleration(v3.ZERO3, v3.ZERO3, vd_0)
    motions: list[LinkAcceleration] = []
    Ws: list[v3.Mat] = []
    for i, link in enumerate(robot.links):
        k = f"T{i + 1}"
        p = parents[i]
        parent, W_parent = (base, v3.ZERO33) if p < 0 else (motions[p], Ws[p])
        motions.append(outward(link, frames[i], parent, W_parent, qd_b[i], qdd_b[i], program, k))
        Ws.append(tilde(program, motions[i].w, motions[i].wd, k))
    extra = {i: PER_BODY * nb + k for k, i in enumerate(asymmetric_bodies(robot))}
    Y: list[list[sp.Expr]] = [[sp.S.Zero] * (PER_BODY * nb + len(extra)) for _ in range(nb)]
    for j, link in enumerate(robot.links):
        carried = {j: motion_subspace(link.joint, link.axis)}  # joint j's unit motion, frame i
        for i in range(j, nb):
            if i != j:
                if parents[i] not in carried:
                    continue  # not in joint j's subtree
                carried[i] = _to_child(frames[i], carried[parents[i]], program, f"s{j + 1}_{i + 1}_")
            cols = _inertial_columns(carried[i], motions[i], Ws[i])
            Y[j][PER_BODY * i : PER_BODY * i + 10] = [program.let(c, f"Y{j + 1}_") for c in cols]
        coulomb = link.friction.coulomb_columns(qd_b[j])
        Y[j][PER_BODY * j + 10 : PER_BODY * j + 13] = [sp.sympify(qdd_b[j]), qd_b[j], coulomb[0]]
        if j in extra:
            Y[j][extra[j]] = coulomb[1]
    return Y


def regressor(robot: Robot, q: Sequence, qd: Sequence, qdd: Sequence, program: Program) -> sp.Matrix:
    """The regressor Y(q, qd, qdd), n x 13 nb (+ fcn columns), with tau = Y pi (joint space; see
    the module docstring).

    Args:
        robot: the model (parameters with values substituted: `Robot.resolved`).
        q, qd, qdd: n symbols each, the independent coordinates.
        program: receives the named intermediates.

    Returns:
        Y over the program's intermediates; column 13 i + k is parameter k of body i + 1 in the order
        of `symdyn.standard_parameters`.
    """
    q_b, qd_b, qdd_b = robot.body_positions(list(q)), robot.body_rates(list(qd)), robot.body_rates(list(qdd))
    Y_b = body_regressor(robot, q_b, qd_b, qdd_b, program)
    columns = [project_vector(robot, [row[c] for row in Y_b], program, "Y") for c in range(len(Y_b[0]))]
    return sp.Matrix(robot.n, len(columns), lambda r, c: columns[c][r])
