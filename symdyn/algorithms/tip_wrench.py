"""The joint torques that balance a wrench at the end effector: tau_tip = J_b(q)^T F_tip.

Modern Robotics' InverseDynamics (Lynch and Park (2017), eq. 8.50) returns
tau = M(q) qdd + c(q, qd) + g(q) + J_b^T(q) F_tip, where F_tip = [m; f] is the wrench the
end effector applies to its environment (moment first), expressed in the end-effector frame
{n+1}, and J_b is the body Jacobian of that frame (angular rows first, in {n+1}). The
end-effector frame is the last link's convention frame (`Link.frame`): frame {n+1} for a
robot from product-of-exponentials data, DH frame n for a DH robot.

Per joint j supporting the last link, with z_j the joint axis and o_j a point on it, p and
R the end-effector frame's origin and orientation (all in the base frame):

    J_b[:, j] = [R^T z_j; R^T (z_j x (p - o_j))]   (revolute)
    J_b[:, j] = [0; R^T z_j]                         (prismatic)

so that the end effector's twist in {n+1} is V_b = J_b qd.

On a floating base (q = [base position, quaternion, joints], qd = [v, w, joint rates] with the
base twist in the base frame, symdyn.model.free_flyer) J_b has NV columns, the base's six first:
a base translation v moves {n+1} by R^T v, a base rotation w turns it by R^T w and moves its
origin by R^T (w x p), so

    J_b[:, base] = [[0, R^T], [R^T, -R^T [p]x]]     (columns v then w; rows omega then v)

and the six base rows of tau_tip = J_b^T F are [R f; R m + p x R f]: the tip wrench carried to
the base, force then moment about the base origin in the base frame (the wrench the base must
supply; the base's pose does not enter).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..errors import SymdynError
from ..model.free_flyer_names import NQ_BASE
from ..model.robot import Robot
from .kinematics import forward_kinematics, point_jacobian

__all__ = ["body_jacobian", "tip_wrench_torque"]


def body_jacobian(robot: Robot, q: Sequence) -> sp.Matrix:
    """J_b (6 x n; 6 x NV on a floating base, the base's columns first: module docstring): the
    end-effector frame's twist [omega; v] per unit joint rate, in that frame.

    Args:
        robot: the model; its last link carries the end-effector frame (`Link.frame`).
        q: n joint positions (symbols or numbers); NQ on a floating base (its pose is not read).
    """
    last = robot.links[-1]
    joints = list(q)[NQ_BASE:] if robot.floating else list(q)
    poses = forward_kinematics(robot, joints)
    J = point_jacobian(robot, -1, list(last.frame.p), joints, poses)  # [v; omega], base frame
    R = poses[-1].R * last.frame.R
    Rt = R.T
    J_b = sp.Matrix.vstack(Rt * J[3:, :], Rt * J[:3, :])
    if not robot.floating:
        return J_b
    p = poses[-1].R * sp.Matrix(last.frame.p) + poses[-1].p  # {n+1}'s origin in the base frame
    cross = sp.Matrix([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])
    base = sp.Matrix.vstack(sp.Matrix.hstack(sp.zeros(3, 3), Rt), sp.Matrix.hstack(Rt, -Rt * cross))
    return sp.Matrix.hstack(base, J_b)


def tip_wrench_torque(robot: Robot, F: Sequence, q: Sequence) -> sp.Matrix:
    """tau_tip = J_b(q)^T F (n x 1, joint space; NV x 1 on a floating base, the base's six rows
    first): the J^T F_tip term of MR's InverseDynamics.

    Args:
        robot: the model.
        F: the wrench [m_x, m_y, m_z, f_x, f_y, f_z] the end effector applies to its
            environment, in the end-effector frame (numbers or SymPy expressions).
        q: n joint positions (symbols or numbers); NQ entries on a floating base.

    Raises:
        SymdynError: F without 6 entries.
    """
    if isinstance(F, (str, bytes)) or len(list(F)) != 6:
        raise SymdynError(f"tip_wrench_torque: F must have 6 entries [m; f], got {F!r}")
    wrench = sp.Matrix([sp.sympify(x) for x in F])
    return body_jacobian(robot, q).T * wrench
