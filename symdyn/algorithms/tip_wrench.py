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
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..errors import SymdynError
from ..model.robot import Robot
from .kinematics import forward_kinematics, point_jacobian

__all__ = ["body_jacobian", "tip_wrench_torque"]


def body_jacobian(robot: Robot, q: Sequence) -> sp.Matrix:
    """J_b (6 x n): the end-effector frame's twist [omega; v] per unit joint rate, in that frame.

    Args:
        robot: the model; its last link carries the end-effector frame (`Link.frame`).
        q: n joint positions (symbols or numbers).
    """
    last = robot.links[-1]
    poses = forward_kinematics(robot, q)
    J = point_jacobian(robot, -1, list(last.frame.p), q, poses)  # [v; omega], base frame
    Rt = (poses[-1].R * last.frame.R).T
    return sp.Matrix.vstack(Rt * J[3:, :], Rt * J[:3, :])


def tip_wrench_torque(robot: Robot, F: Sequence, q: Sequence) -> sp.Matrix:
    """tau_tip = J_b(q)^T F (n x 1, joint space): the J^T F_tip term of MR's InverseDynamics.

    Args:
        robot: the model.
        F: the wrench [m_x, m_y, m_z, f_x, f_y, f_z] the end effector applies to its
            environment, in the end-effector frame (numbers or SymPy expressions).
        q: n joint positions (symbols or numbers).

    Raises:
        SymdynError: F without 6 entries.
    """
    if isinstance(F, (str, bytes)) or len(list(F)) != 6:
        raise SymdynError(f"tip_wrench_torque: F must have 6 entries [m; f], got {F!r}")
    wrench = sp.Matrix([sp.sympify(x) for x in F])
    return body_jacobian(robot, q).T * wrench
