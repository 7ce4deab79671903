"""Frames of a floating robot, symbolic: the pose, Jacobians (6 x NV, with the base's columns)
and drift of a named frame, and the centre of mass with its Jacobian and drift.

The base frame is at (p, R = world_R_base) given by the free flyer's coordinates
(symdyn.model.free_flyer); symdyn.algorithms.frame_kinematics gives everything relative to the
base (a floating robot's Robot.base is the identity). For a frame F at r = base_p_F, base_R_F:

* pose: world_T_F = (R, p) base_T_F;
* Jacobian world-aligned at F's origin (Pinocchio's LOCAL_WORLD_ALIGNED) on v = [v_b, w_b, qd]:
  the base's columns [R, -R [r]x; 0, R] (the base twist moves F's origin by v_b + w_b x r,
  base axes), the joints' blockdiag(R, R) J_base (J_base the fixed-base Jacobian, base axes);
* Jacobian in F's axes (LOCAL): the base's columns blockdiag(F_R_base, F_R_base) [1, -[r]x; 0, 1],
  the joints' the fixed-base local Jacobian (it never involves the base);
* drift Jdot v at vdot = 0, world-aligned: the classical acceleration of F's origin and F's
  angular acceleration when the base's body twist is constant, from the motions of
  symdyn.algorithms.centroidal (instantaneous base axes), turned by R;
* centre of mass, its Jacobian (3 x NV) and drift: symdyn.algorithms.centroidal's (the base
  body included).
"""

from __future__ import annotations

import sympy as sp

from ..spatial import vectors as v3
from ..spatial.transform import Transform
from .centroidal import Centroidal
from .frame_kinematics import FrameKinematics

__all__ = ["FloatingFrames", "skew"]


def skew(r) -> sp.Matrix:
    """[r]x, the 3 x 3 matrix of r x ."""
    return sp.Matrix([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])


class FloatingFrames:
    """The frame quantities of a floating robot (module docstring) over one Program.

    Args:
        fk: the robot's frame kinematics relative to its base (joint coordinates only).
        cen: its centroidal quantities (which hold the base's coordinates and the motions).
    """

    def __init__(self, fk: FrameKinematics, cen: Centroidal) -> None:
        assert cen.base_q is not None and fk.robot.base.is_identity()
        self.fk, self.cen, self.program = fk, cen, fk.program
        self.R = sp.Matrix(cen.rotation)
        self.p = sp.Matrix(cen.base_q[:3])

    def _named(self, M: sp.Matrix, hint: str) -> sp.Matrix:
        return M.applyfunc(lambda x: self.program.let(x, hint))

    def pose(self, name: str) -> sp.Matrix:
        """world_T_F (4 x 4)."""
        F = self.fk.pose(name)
        local = Transform(sp.ImmutableMatrix(F[:3, :3]), sp.ImmutableMatrix(F[:3, 3]))
        T = Transform(sp.ImmutableMatrix(self.R), sp.ImmutableMatrix(self.p)) @ local
        return self._named(T.matrix(), "FP")

    def jacobian(self, name: str, reference: str = "world") -> sp.Matrix:
        """J (6 x NV): world-aligned at F's origin ("world") or in F's axes ("local")."""
        T = self.fk.pose(name)
        r, R_F = T[:3, 3], T[:3, :3]
        base = sp.Matrix(sp.BlockMatrix([[sp.eye(3), -skew(r)], [sp.zeros(3), sp.eye(3)]]))
        if reference == "world":
            rot = sp.diag(self.R, self.R)
            J = sp.Matrix.hstack(rot * base, rot * self.fk.jacobian(name, "world"))
        else:
            J = sp.Matrix.hstack(sp.diag(R_F.T, R_F.T) * base, self.fk.jacobian(name, "local"))
        return self._named(J, "FJ")

    def jacobian_dot_qd(self, name: str) -> sp.Matrix:
        """Jdot v (6 x 1) at vdot = 0: classical acceleration of F's origin, then F's angular
        acceleration, world-aligned."""
        f = self.fk.frame(name)
        motions = self.cen.motions()
        w, wd, _, a = motions[f.link] if f.link >= 0 else self.cen.root
        o = v3.vec(list(self.fk.poses[f.link].p)) if f.link >= 0 else v3.ZERO3
        r = v3.vec(list(self.fk.pose(name)[:3, 3]))
        d = v3.sub(r, o)
        acc = v3.add(a, v3.cross(wd, d), v3.cross(w, v3.cross(w, d)))
        R = v3.mat(self.R)
        return self._named(sp.Matrix([*v3.mul(R, acc), *v3.mul(R, wd)]), "FJd")

    def com(self) -> sp.Matrix:
        return self.cen.com()

    def com_jacobian(self) -> sp.Matrix:
        return self.cen.com_jacobian()

    def com_jacobian_dot_qd(self) -> sp.Matrix:
        """The centre of mass's acceleration at vdot = 0 (3 x 1): Adot_g v's linear part over m."""
        inv = self.program.let(1 / self.cen.mass, "cim")
        return self._named(self.cen.drift()[:3, :] * inv, "FJcd")
