"""Which joints make the joint-space mass matrix M(q) singular by construction, and why.

Forward dynamics solves M qdd = tau - bias by the unrolled factorisation M = L D L^T
(symdyn.algorithms.derivatives.ldlt_factor, eliminated in `elimination_order`):

    D_j = M_jj - sum_{k<j} L_jk^2 D_k,   L_ij = (M_ij - sum_{k<j} L_ik L_jk D_k) / D_j.

M is positive semi-definite, so a pivot D_j that is exactly zero means a zero row and column
of the Schur complement left after the earlier eliminations: M is singular for every q, and
every function that inverts M would divide by that zero. This module factorises the derived
M, numbers substituted (a robot's valued parameters are already in), and reports the pivots
that are exactly zero, each with its cause:

- "massless": the joint moves nothing with mass or inertia (its subtree has zero mass and
  inertia and the joint no rotor inertia; symdyn.model.robot.Robot.idle_joints);
- "on_axis": M_jj = 0 although the subtree has mass: a revolute joint whose moving mass lies
  on its own axis with no rotational inertia about that axis (a point mass on the axis, as
  the Robotics Toolbox's UR3 and UR5 are written); M_jj = s^T Ic s = 0;
- "dependent": M_jj is not zero, but the joint moves the bodies only as the joints
  eliminated before it do (its column of M is a combination of theirs).

A free parameter may take any value: a pivot that depends on one is not zero, so with
symbolic masses only pivots that are identically zero count (and the massless joints that
Robot.idle_joints finds on the values given). A pivot that is zero only through an identity
the factorisation does not apply (sin^2 + cos^2 = 1 across intermediates) is not seen here.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from ..errors import SINGULAR_REASONS as REASONS
from ..model.robot import Robot
from ..symbolic.program import Program
from .derivatives import elimination_order

__all__ = ["SingularJoint", "REASONS", "singular_joints", "describe_singular"]


@dataclass(frozen=True)
class SingularJoint:
    """An independent coordinate whose pivot of M = L D L^T is exactly zero (module docstring).

    `coordinate` is its index in q, `link` the index in Robot.links of the link its joint
    moves (the link whose own coordinate it is), `reason` a key of REASONS.
    """

    coordinate: int
    link: int
    reason: str


def _zero_pivots(M: sp.Matrix, order: Sequence[int]) -> list[int]:
    """The coordinates whose pivot D_j of M (eliminated in `order`) is exactly zero. Such a
    pivot's column of L is zero too (M positive semi-definite), so the factorisation goes on."""
    A = M.extract(list(order), list(order))
    n = A.rows
    program = Program()  # a scratch program: the pivots only need to be compared with zero
    L = sp.zeros(n, n)
    D: list[sp.Expr] = [sp.S.Zero] * n
    zero = []
    for j in range(n):
        D[j] = program.let(A[j, j] - sum((L[j, k] ** 2 * D[k] for k in range(j)), sp.S.Zero), "D")
        if D[j] == 0:
            zero.append(order[j])
            continue
        for i in range(j + 1, n):
            s = A[i, j] - sum((L[i, k] * L[j, k] * D[k] for k in range(j)), sp.S.Zero)
            L[i, j] = program.let(s / D[j], "L") if s != 0 else sp.S.Zero
    return sorted(zero)


def singular_joints(robot: Robot, M: sp.Matrix) -> tuple[SingularJoint, ...]:
    """The joints whose pivot of M is exactly zero, with their causes (module docstring).

    Args:
        robot: the robot M was derived from (its valued parameters substituted).
        M: its n x n mass matrix, over named intermediates or closed-form.

    Returns:
        One SingularJoint per such coordinate, in increasing order; empty when M can be inverted
        as far as its numbers tell.
    """
    idle = {robot.coordinates[i].index for i in robot.idle_joints()}
    zero = set(_zero_pivots(M, elimination_order(robot.n, robot.is_chain))) | idle
    own = {c.index: i for i, c in enumerate(robot.coordinates) if robot.links[i].mimic is None}
    out = []
    for c in sorted(zero):
        reason = "massless" if c in idle else "on_axis" if M[c, c] == 0 else "dependent"
        out.append(SingularJoint(c, own[c], reason))
    return tuple(out)


def describe_singular(robot: Robot, joints: Sequence[SingularJoint]) -> str:
    """One sentence naming each singular joint as the robot file does (the joint of link 'X',
    by the link's name and number, and by its own name where the file names joints: URDF, MJCF)
    and why: "the joint of link 'l2' (link 2) moves ..."."""

    def name(k: int) -> str:
        link = robot.links[k]
        own = "" if link.joint_name is None else f"joint '{link.joint_name}', "
        return f"the joint of link '{link.name}' ({own}link {k + 1})"

    names = [name(j.link) for j in joints]
    return "; ".join(f"{name} {REASONS[j.reason]}" for name, j in zip(names, joints, strict=True))
