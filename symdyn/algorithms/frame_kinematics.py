"""Frame kinematics, symbolic: the pose, Jacobians and acceleration drift of any named frame, and
the centre of mass with its Jacobian, over the named intermediates of one Program.

For a frame F fixed to link k at k_T_F (symdyn.model.frames), in the world (the robot's base
frame placed at world_T_base, Robot.base):

* pose: world_T_F = world_T_base base_T_k(q) k_T_F (4 x 4), base_T_k composed along the tree
  (symdyn.algorithms.kinematics.forward_kinematics), every entry a named intermediate;
* Jacobian world-aligned at F's origin r (Pinocchio's LOCAL_WORLD_ALIGNED, the geometric
  Jacobian of Spong et al. (2006), sec. 4.6), rows v_x v_y v_z w_x w_y w_z, 6 x n: per
  supporting joint j, revolute [z_j x (r - o_j); z_j], prismatic [z_j; 0], z_j and o_j the
  joint axis and body origin in the world (kinematics.point_jacobian on the world poses);
* Jacobian in F's own axes (Pinocchio's LOCAL): blockdiag(F_R_k, F_R_k) times link k's body
  Jacobian at r (kinematics.body_point_jacobian), which never involves the base pose;
* drift Jdot qd = [a_F; wd_F] at qdd = 0, world-aligned: the classical acceleration of F's
  origin and F's angular acceleration (Pinocchio's getFrameClassicalAcceleration at a = 0,
  LOCAL_WORLD_ALIGNED), by the outward recursion over the supporting bodies, world axes,
  d_i = o_i - o_lambda(i):

      w_i  = w_p + z_i qd_i                         (revolute; prismatic: w_i = w_p)
      wd_i = wd_p + w_p x z_i qd_i                  (revolute; prismatic: wd_i = wd_p)
      a_i  = a_p + wd_p x d_i + w_p x (w_p x d_i)  [+ 2 w_p x z_i qd_i, prismatic]
      a_F  = a_k + wd_k x (r - o_k) + w_k x (w_k x (r - o_k)),   wd_F = wd_k

  (the base at rest: w = wd = a = 0; the qdd terms J qdd are left out);
* centre of mass c = sum_i m_i c_i / m, c_i link i's in the world; Jc = sum_i m_i Jv_i / m
  (3 x n, Jv_i the linear rows of the Jacobian of c_i) and Jc_dot qd = sum_i m_i a_ci / m
  (a_ci by the last line of the recursion at c_i).

Mimic joints: the recursions run on the bodies at q_b, qd_b = S qd, so every Jacobian is
with respect to the n independent coordinates (J = J_b S, as for M).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.frames import Frame
from ..model.robot import Robot
from ..spatial import vectors as v3
from ..spatial.transform import Transform
from ..symbolic.program import Program
from .kinematics import body_point_jacobian, forward_kinematics, point_jacobian

__all__ = ["FrameKinematics"]


def _named(T: Transform, program: Program, hint: str) -> Transform:
    R = sp.ImmutableMatrix(3, 3, [program.let(x, f"{hint}R") for x in T.R])
    p = sp.ImmutableMatrix(3, 1, [program.let(x, f"{hint}p") for x in T.p])
    return Transform(R, p)


def _key(name: str | Frame) -> str:
    """The cache key of a frame given by name or as a Frame."""
    return name.name if isinstance(name, Frame) else name


def _column(v: v3.Vec) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(3, 1, list(v))


class FrameKinematics:
    """The frame quantities of one robot over one Program (module docstring), cached per frame.

    Args:
        robot: the model with its valued parameters substituted (Robot.resolved()).
        q, qd: the n independent joint symbols (or numbers).
        program: receives the named intermediates (a copy of the dynamics' program, say).
    """

    def __init__(self, robot: Robot, q: Sequence, qd: Sequence, program: Program) -> None:
        self.robot = robot
        self.q, self.qd = list(q), list(qd)
        self.program = program
        self._poses: list[Transform] | None = None
        self._motion: dict[int, tuple[v3.Vec, v3.Vec, v3.Vec]] = {}
        self._cache: dict[tuple, sp.Matrix] = {}

    def frame(self, name: str | Frame) -> Frame:
        """The frame `name` of the robot (Robot.frame: unknown names are refused), or a Frame
        given as such (a loop's closure frame, symdyn.model.loops)."""
        if isinstance(name, Frame):
            return name
        return self.robot.frame(name, "frame kinematics")

    @property
    def poses(self) -> list[Transform]:
        """world_T_i of every body (named intermediates)."""
        if self._poses is None:
            base = self.robot.base
            poses = forward_kinematics(self.robot, self.q, self.program)
            if not base.is_identity():
                poses = [_named(base @ T, self.program, f"W{i + 1}") for i, T in enumerate(poses)]
            self._poses = poses
        return self._poses

    def _link_pose(self, k: int) -> Transform:
        return self.robot.base if k < 0 else self.poses[k]

    def pose(self, name: str | Frame) -> sp.Matrix:
        """world_T_F, 4 x 4 (rotation and origin of F in the world)."""
        key = ("pose", _key(name))
        if key not in self._cache:
            f = self.frame(name)
            T = self._link_pose(f.link) @ f.placement
            if not f.placement.is_identity():
                T = _named(T, self.program, "P")
            self._cache[key] = T.matrix()
        return self._cache[key]

    def jacobian(self, name: str | Frame, reference: str = "world") -> sp.Matrix:
        """J (6 x n), rows v_x v_y v_z w_x w_y w_z: world-aligned at F's origin ("world") or in
        F's own axes ("local"). A frame on the base has J = 0."""
        assert reference in ("world", "local"), reference
        key = (reference, _key(name))
        if key not in self._cache:
            f = self.frame(name)
            n = self.robot.n
            if f.link < 0:
                J = sp.zeros(6, n)
            elif reference == "world":
                J = point_jacobian(self.robot, f.link, list(f.placement.p), poses=self.poses)
            else:
                Jk = body_point_jacobian(self.robot, f.link, list(f.placement.p), self.q, self.program)
                Rt = f.placement.R.T
                J = sp.Matrix.vstack(Rt * Jk[:3, :], Rt * Jk[3:, :])
            self._cache[key] = J.applyfunc(lambda x: self.program.let(x, "J"))
        return self._cache[key]

    def _body_motion(self, i: int) -> tuple[v3.Vec, v3.Vec, v3.Vec]:
        """(w_i, wd_i, a_i) at qdd = 0, world axes (module docstring), named; memoised."""
        if i in self._motion:
            return self._motion[i]
        zero = (sp.S.Zero,) * 3
        p = self.robot.parents[i]
        w_p, wd_p, a_p = self._body_motion(p) if p >= 0 else (zero, zero, zero)
        link, T = self.robot.links[i], self.poses[i]
        rate = self.robot.body_rates(self.qd)[i]
        z = v3.vec(T.R * link.axis)
        d = v3.sub(v3.vec(T.p), v3.vec(self._link_pose(p).p))
        a = v3.add(a_p, v3.cross(wd_p, d), v3.cross(w_p, v3.cross(w_p, d)))
        if link.joint == "revolute":
            zq = v3.scale(rate, z)
            w, wd = v3.add(w_p, zq), v3.add(wd_p, v3.cross(w_p, zq))
        else:
            w, wd = w_p, wd_p
            a = v3.add(a, v3.scale(2 * rate, v3.cross(w_p, z)))
        tag = f"{i + 1}_"
        out = (
            self.program.let_vector(w, f"w{tag}"),
            self.program.let_vector(wd, f"wd{tag}"),
            self.program.let_vector(a, f"a{tag}"),
        )
        self._motion[i] = out
        return out

    def _point_acceleration(self, k: int, r: v3.Vec) -> v3.Vec:
        """a of a point r (world) fixed to body k at qdd = 0."""
        w, wd, a = self._body_motion(k)
        d = v3.sub(r, v3.vec(self.poses[k].p))
        return v3.add(a, v3.cross(wd, d), v3.cross(w, v3.cross(w, d)))

    def jacobian_dot_qd(self, name: str | Frame) -> sp.Matrix:
        """Jdot qd = [a_F; wd_F] (6 x 1) at qdd = 0, world-aligned at F's origin."""
        key = ("drift", _key(name))
        if key not in self._cache:
            f = self.frame(name)
            if f.link < 0:
                out = [sp.S.Zero] * 6
            else:
                r = v3.vec(self.poses[f.link].apply(list(f.placement.p)))
                out = [*self._point_acceleration(f.link, r), *self._body_motion(f.link)[1]]
            self._cache[key] = sp.Matrix(6, 1, [self.program.let(x, "Jd") for x in out])
        return self._cache[key]

    @property
    def mass(self) -> sp.Expr:
        """The robot's total mass m (the moving links')."""
        return sp.Add(*[link.mass for link in self.robot.links])

    def _com_points(self) -> list[v3.Vec]:
        return [v3.vec(T.apply(list(link.com))) for T, link in zip(self.poses, self.robot.links, strict=True)]

    def _weighted(self, terms: list[sp.Matrix], rows: int, hint: str) -> sp.Matrix:
        """sum_i m_i terms_i / m, entries named."""
        inv = self.program.let(1 / self.mass, "im")
        total = sp.zeros(rows, terms[0].cols)
        for link, t in zip(self.robot.links, terms, strict=True):
            if link.mass != 0:
                total += link.mass * t
        return total.applyfunc(lambda x: self.program.let(x * inv, hint))

    def com(self) -> sp.Matrix:
        """c(q) (3 x 1), world frame."""
        if "com" not in self._cache:
            self._cache["com"] = self._weighted([_column(c) for c in self._com_points()], 3, "c")
        return self._cache["com"]

    def com_jacobian(self) -> sp.Matrix:
        """Jc (3 x n), world frame: dc/dt = Jc qd."""
        if "Jc" not in self._cache:
            terms = [
                point_jacobian(self.robot, i, list(link.com), poses=self.poses)[:3, :]
                for i, link in enumerate(self.robot.links)
            ]
            self._cache["Jc"] = self._weighted(terms, 3, "Jc")
        return self._cache["Jc"]

    def com_jacobian_dot_qd(self) -> sp.Matrix:
        """Jc_dot qd (3 x 1), world frame: the centre of mass's acceleration at qdd = 0."""
        if "Jcd" not in self._cache:
            points = self._com_points()
            terms = [_column(self._point_acceleration(i, c)) for i, c in enumerate(points)]
            self._cache["Jcd"] = self._weighted(terms, 3, "Jcd")
        return self._cache["Jcd"]
