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

A floating robot's M (NV x NV, the base's six coordinates first) is factorised as its forward
dynamics does: the joints from the last to the first, then the base's block, last. The joints'
pivots are those of the joint block M[6:, 6:] (the base is eliminated after them) and are found
as above. The base's six pivots are those of the Schur complement the joints leave, the base's
articulated-body inertia: a zero one means the base can move while every body with mass stands
still ("base": a massless base body on a revolute joint turns about that joint's axis while the
links do not move). They are intermediates of every joint, zero only through identities, so they
are decided on numbers instead: on `samples`, M evaluated at random joint positions (and random
values of the free parameters, which keeps the test generic: a pivot zero at random values is
zero everywhere, with probability one), a base pivot at most BASE_TOLERANCE of M's largest
diagonal entry in every sample is zero.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..errors import SINGULAR_REASONS as REASONS
from ..model.free_flyer_names import BASE_VELOCITY_NAMES, NV_BASE
from ..model.robot import Robot
from ..symbolic.program import Program
from .derivatives import elimination_order

__all__ = ["SingularJoint", "REASONS", "BASE_TOLERANCE", "singular_joints", "describe_singular"]

#: A floating robot's base pivot at most this fraction of M's largest diagonal entry is zero
#: (rounding leaves a true zero near 1e-16 of it; a real one is far above).
BASE_TOLERANCE = 1e-10


@dataclass(frozen=True)
class SingularJoint:
    """An independent coordinate whose pivot of M = L D L^T is exactly zero (module docstring).

    `coordinate` is its index in qd (in q too on a fixed base; on a floating base the index in
    the velocity vector of NV entries, the base's six first), `link` the index in Robot.links of
    the link its joint moves (the link whose own coordinate it is; None for a coordinate of the
    base), `reason` a key of REASONS.
    """

    coordinate: int
    link: int | None
    reason: str


def _zero_pivots(M: sp.Matrix, order: Sequence[int]) -> list[int]:
    """The coordinates whose pivot D_j of M (eliminated in `order`) is exactly zero. Such a
    pivot's column of L is zero too (M positive semi-definite), so the factorisation goes on.
    The sums run over the nonzero entries of L only (the same sums: the others add exact
    zeros), so a tree, eliminated without fill-in, costs its ancestries, not n^3."""
    n = M.rows
    A = M.extract(list(order), list(order)).tolist()
    program = Program()  # a scratch program: the pivots only need to be compared with zero
    L: list[dict[int, sp.Expr]] = [{} for _ in range(n)]  # row i: k -> L_ik, nonzero ones
    D: list[sp.Expr] = [sp.S.Zero] * n
    zero = []
    for j in range(n):
        row = L[j]
        D[j] = program.let(A[j][j] - sum((v**2 * D[k] for k, v in row.items()), sp.S.Zero), "D")
        if D[j] == 0:
            zero.append(order[j])
            continue
        for i in range(j + 1, n):
            other = L[i]
            s = A[i][j] - sum((other[k] * v * D[k] for k, v in row.items() if k in other), sp.S.Zero)
            if s != 0:
                other[j] = program.let(s / D[j], "L")
    return sorted(zero)


def _zero_base_pivots(M: np.ndarray, zero_joints: set[int]) -> set[int]:
    """The base coordinates (0..5) whose pivot is zero in the numeric NV x NV M of a floating
    robot, eliminated joints last to first then the base (module docstring); the joints of
    `zero_joints` (indices in M) have a zero pivot and a zero column of L."""
    nv = M.shape[0]
    order = list(reversed(range(nv)))
    A = M[np.ix_(order, order)].astype(float)
    scale = max(float(np.max(np.abs(np.diag(A)))), np.finfo(float).tiny)
    zero = set()
    for j, c in enumerate(order):
        d = A[j, j]
        if c in zero_joints or abs(d) <= BASE_TOLERANCE * scale:
            zero |= {c} & set(range(NV_BASE))  # a joint's numeric zero only skipped: decided above
            continue
        col = A[j + 1 :, j] / d
        A[j + 1 :, j + 1 :] -= np.outer(col, A[j, j + 1 :])
    return zero


def singular_joints(
    robot: Robot, M: sp.Matrix, samples: Sequence[np.ndarray] = ()
) -> tuple[SingularJoint, ...]:
    """The joints whose pivot of M is exactly zero, with their causes (module docstring).

    Args:
        robot: the robot M was derived from (its valued parameters substituted).
        M: its n x n mass matrix (NV x NV on a floating base), over named intermediates or
            closed-form.
        samples: on a floating base, M's values at a few random states (module docstring), which
            decide the base's pivots; none: the base's pivots are not checked.

    Returns:
        One SingularJoint per such coordinate, in increasing order; empty when M can be inverted
        as far as its numbers tell.
    """
    base = NV_BASE if robot.floating else 0
    idle = {robot.coordinates[i].index + base for i in robot.idle_joints()}
    joints = M[base:, base:]
    order = elimination_order(robot.n, robot.is_chain and not robot.floating)
    zero = {c + base for c in _zero_pivots(joints, order)} | idle
    if robot.floating and samples:
        zero |= set.intersection(*(_zero_base_pivots(np.asarray(s), zero) for s in samples))
    own = {c.index + base: i for i, c in enumerate(robot.coordinates) if robot.links[i].mimic is None}
    out = []
    for c in sorted(zero):
        if c < base:
            out.append(SingularJoint(c, None, "base"))
            continue
        reason = "massless" if c in idle else "on_axis" if M[c, c] == 0 else "dependent"
        out.append(SingularJoint(c, own[c], reason))
    return tuple(out)


def describe_singular(robot: Robot, joints: Sequence[SingularJoint]) -> str:
    """One sentence naming each singular joint as the robot file does (the joint of link 'X',
    by the link's name and number, and by its own name where the file names joints: URDF, MJCF)
    and why: "the joint of link 'l2' (link 2) moves ..."."""

    def name(k: int | None, coordinate: int) -> str:
        if k is None:
            return f"the base's coordinate {BASE_VELOCITY_NAMES[coordinate]} (entry {coordinate + 1} of qd)"
        link = robot.links[k]
        own = "" if link.joint_name is None else f"joint '{link.joint_name}', "
        return f"the joint of link '{link.name}' ({own}link {k + 1})"

    names = [name(j.link, j.coordinate) for j in joints]
    return "; ".join(f"{name} {REASONS[j.reason]}" for name, j in zip(names, joints, strict=True))
