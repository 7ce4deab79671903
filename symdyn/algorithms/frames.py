"""Joint frames for the symbolic recursions, and rotations of inertia tensors between them.

Link i's body frame sits in its parent's (link lambda(i), or the base: a kinematic tree,
symdyn.model.topology) at p_i with orientation
R_i = B_i Rot(a_i, q_i) (revolute) or R_i = B_i (prismatic), B_i the constant
rotation of the joint's placement (symdyn.model.robot). The composite-body
recursions move symmetric 3x3 tensors (rotational inertias and their rates of
change) into the parent frame, R J R^T. For a joint about a coordinate axis k,
with (i, j) the other two axes in right-handed order, c = cos q and s = sin q,
the rotation about k gives

    t = e s^2 + 2 J_ij c s,   J'_ii = J_ii - t,   J'_jj = J_jj + t,   J'_ij = e c s + J_ij (1 - 2 s^2),
    J'_ik = c J_ik - s J_jk,  J'_jk = s J_ik + c J_jk,  J'_kk = J_kk,

e = J_ii - J_jj: the identity c^2 + s^2 = 1 is used
up front, so a tensor symmetric about the joint axis (J_ii = J_jj, J_ij = 0)
passes through with no trigonometric term at all, and the constant B_i is
applied after with zero-aware products.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import sympy as sp

from ..model.robot import Robot
from ..spatial import vectors as v3
from ..spatial.motion import Force
from ..spatial.transform import coordinate_axis
from ..symbolic.program import Program

__all__ = ["AxisTurn", "JointFrame", "joint_frames"]

#: the two axes spanning the plane of a rotation about x, y or z, in right-handed order
_PLANES = {0: (1, 2), 1: (2, 0), 2: (0, 1)}


class AxisTurn(NamedTuple):
    """A rotation by q about coordinate axis k; (i, j, k) a right-handed order of the axes."""

    i: int
    j: int
    k: int
    cos: sp.Expr
    sin: sp.Expr


@dataclass(frozen=True)
class JointFrame:
    """Body frame i in its parent's (frame lambda(i), written i-1 below as in a chain):
    R = parent_R_i = B Rot(axis, q_i), p = the origin of frame i in the parent frame (parent
    axes), B the constant rotation of the placement."""

    R: v3.Mat
    p: v3.Vec
    B: v3.Mat
    #: the joint's own rotation when it turns about a coordinate axis, else None
    turn: AxisTurn | None = None

    def rotate_symmetric(
        self, J: Sequence[Sequence[sp.Expr]], program: Program, hint: str
    ) -> list[list[sp.Expr]]:
        """R J R^T: a symmetric tensor J in frame i's axes turned into frame i-1's (Grupen,
        "Dynamics" (2015), slide 10). Entries of the result, not yet named."""
        if self.turn is None:
            return _congruence(self.R, J)
        i, j, k, c, s = self.turn
        e = v3.sum_terms((J[i][i], -J[j][j]))
        out = [[sp.S.Zero] * 3 for _ in range(3)]
        out[i][i], out[j][j] = J[i][i], J[j][j]
        if e is not sp.S.Zero or J[i][j] is not sp.S.Zero:
            ss = program.let(s * s, f"{hint}ss_")
            cs = program.let(c * s, f"{hint}cs_")
            c2 = program.let(1 - 2 * ss, f"{hint}c2_")
            t = program.let(v3.sum_terms((v3.product(e, ss), v3.product(J[i][j], 2 * cs))), hint)
            out[i][i] = v3.sum_terms((J[i][i], -t))
            out[j][j] = v3.sum_terms((J[j][j], t))
            out[i][j] = v3.sum_terms((v3.product(e, cs), v3.product(J[i][j], c2)))
        out[i][k] = v3.sum_terms((v3.product(c, J[i][k]), -v3.product(s, J[j][k])))
        out[j][k] = v3.sum_terms((v3.product(s, J[i][k]), v3.product(c, J[j][k])))
        out[k][k] = J[k][k]
        for r, q in ((j, i), (k, i), (k, j)):
            out[r][q] = out[q][r]
        return _congruence(self.B, out)

    def force_to_parent(self, force_i: Force, program: Program, hint: str) -> Force:
        """A spatial force carried from frame i to frame i-1 (Featherstone 2008, sec. 2.8).

        Args:
            force_i: (moment n about frame i's origin, force f), frame i's axes.

        Returns:
            (R n + p x R f, R f): the moment about frame i-1's origin and the force, in frame
            i-1's axes; R f is named (it appears in both).
        """
        n, f = force_i
        Rf = program.let_vector(v3.mul(self.R, f), hint)
        return Force(v3.add(v3.mul(self.R, n), v3.cross(self.p, Rf)), Rf)


def _congruence(R: v3.Mat, J: Sequence[Sequence[sp.Expr]]) -> list[list[sp.Expr]]:
    """R J R^T, skipping zero and unit factors."""
    RJ = [[v3.dot(R[r], (J[0][c], J[1][c], J[2][c])) for c in range(3)] for r in range(3)]
    return [[v3.dot(RJ[r], R[c]) for c in range(3)] for r in range(3)]


def joint_frames(robot: Robot, q: Sequence) -> list[JointFrame]:
    """R_i, p_i (and the factors of R_i) per link: body i in its parent's body frame.

    Args:
        robot: the model (symdyn.model.robot), nb links (bodies).
        q: nb joint positions of the bodies (symbols, numbers or, for mimic joints,
            expressions of the independent coordinates: Robot.body_positions).

    Returns:
        nb frames; frame i maps frame i's coordinates into its parent's (robot.parents[i];
        the base frame for a link on the base).
    """
    assert len(q) == robot.nb, (len(q), robot.nb)
    out = []
    for link, qi in zip(robot.links, q, strict=True):
        T = link.joint_transform(qi)
        turn = None
        coord = coordinate_axis(list(link.axis)) if link.joint == "revolute" else None
        if coord is not None:
            k, sign = coord
            angle = qi if sign == 1 else -qi
            turn = AxisTurn(*_PLANES[k], k, sp.cos(angle), sp.sin(angle))
        out.append(JointFrame(v3.mat(T.R), v3.vec(T.p), v3.mat(link.placement.R), turn))
    return out
