"""The contact Jacobian Jc and the drift gamma = Jc_dot qd of a robot's contacts, symbolic.

A robot's contacts (symdyn.model.contacts) stack their rows in declaration order, NLAMBDA rows
over the NV velocity coordinates (a floating robot's base twist in the base frame first), from
the frame quantities of symdyn.algorithms.frame_kinematics (fixed base) or
symdyn.algorithms.floating_frames (floating base), in Pinocchio's conventions:

* point contact at frame F (CONTACT_3D, LOCAL_WORLD_ALIGNED), 3 rows: the linear rows of F's
  world-aligned Jacobian J_W (v_F = J_W[:3] qd, the velocity of F's origin in world axes), and the
  classical acceleration of F's origin at qdd = 0, the linear part of Jdot qd (world axes):

      Jc = J_W[:3],   gamma = a_F = (Jdot qd)[:3];

* 6d contact at F (CONTACT_6D, LOCAL), 6 rows: F's Jacobian in its own axes J_L (linear then
  angular), and F's spatial acceleration in its own axes at qdd = 0 (Pinocchio's
  getFrameAcceleration(LOCAL), not the classical one), with R = world_R_F, v and w F's linear and
  angular velocity (world, v = J_W[:3] qd, w = J_W[3:] qd), a_F and wd_F the classical drift:

      Jc = J_L,   gamma = [R^T (a_F - w x v); R^T wd_F]

  (the classical acceleration of a point is the spatial one plus w x v; both in F's axes, the
  spatial linear acceleration is R^T a_F - (R^T w) x (R^T v) = R^T (a_F - w x v)).

With these, a contact that holds (its frame's velocity stays zero) satisfies Jc qdd + gamma = 0.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.contacts import Contact
from ..spatial import vectors as v3
from ..symbolic.program import Program

__all__ = ["ContactKinematics"]


class ContactKinematics:
    """Jc (NLAMBDA x NV) and gamma (NLAMBDA) of `contacts` over one Program (module docstring).

    Args:
        frames: the robot's frame quantities (FrameKinematics on a fixed base, FloatingFrames on a
            floating one) over `program`.
        contacts: the contacts, rows in their order.
        qd: the NV velocity symbols the frames' drifts are written in.
        program: receives the named intermediates.
    """

    def __init__(
        self, frames, contacts: Sequence[Contact], qd: Sequence[sp.Symbol], program: Program
    ) -> None:
        self.frames, self.contacts, self.qd, self.program = frames, tuple(contacts), list(qd), program

    def row_contacts(self) -> list[int]:
        """The index of the contact of each row (NLAMBDA entries)."""
        return [k for k, c in enumerate(self.contacts) for _ in range(c.rows)]

    def jacobian(self) -> sp.Matrix:
        """Jc, NLAMBDA x NV: per contact, its rows of the world-aligned (point) or local (6d)
        Jacobian of its frame."""
        blocks = [
            self.frames.jacobian(c.frame, "world")[:3, :]
            if c.kind == "point"
            else self.frames.jacobian(c.frame, "local")
            for c in self.contacts
        ]
        return sp.Matrix.vstack(*blocks)

    def drift(self) -> sp.Matrix:
        """gamma = Jc_dot qd at qdd = 0 (NLAMBDA x 1): a point's classical acceleration
        (world-aligned), a 6d frame's spatial acceleration in its own axes."""
        rows: list[sp.Expr] = []
        for c in self.contacts:
            drift = self.frames.jacobian_dot_qd(c.frame)
            if c.kind == "point":
                rows += list(drift[:3, 0])
                continue
            rows += self._spatial_local(c.frame, drift)
        return sp.Matrix(len(rows), 1, rows)

    def _spatial_local(self, frame: str, drift: sp.Matrix) -> list[sp.Expr]:
        """[R^T (a_F - w x v); R^T wd_F] of the module docstring, named."""
        prog = self.program
        J = self.frames.jacobian(frame, "world")
        twist = [
            prog.let(sp.Add(*[J[i, j] * self.qd[j] for j in range(J.cols) if J[i, j] != 0]), "cv")
            for i in range(6)
        ]
        v, w = v3.vec(twist[:3]), v3.vec(twist[3:])
        linear = v3.sub(v3.vec(list(drift[:3, 0])), v3.cross(w, v))
        R = v3.mat(self.frames.pose(frame)[:3, :3])
        out = [*v3.mul_t(R, linear), *v3.mul_t(R, v3.vec(list(drift[3:, 0])))]
        return [prog.let(x, "cg") for x in out]
