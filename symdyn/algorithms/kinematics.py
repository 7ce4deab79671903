"""Forward kinematics and geometric Jacobians, symbolic (SymPy) and numeric.

All poses are body frames of the links expressed in the base frame:
base_T_i = parent_T_1(q_1) @ ... @ parent_T_i(q_i) (see `symdyn.model.robot`). The
geometric Jacobian J = [Jv; Jw] (6 x n) of a point r fixed to link k maps joint
velocities to the point's linear velocity and the link's angular velocity, both
in the base frame:
    revolute j <= k:  Jv_j = z_j x (r - o_j),  Jw_j = z_j
    prismatic j <= k: Jv_j = z_j,              Jw_j = 0
with z_j the joint axis and o_j the body origin of link j, in the base frame.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np
import sympy as sp

from ..model.robot import Robot
from ..model.symbols import joint_symbols
from ..spatial.transform import Transform
from ..symbolic.program import Program

__all__ = [
    "link_transforms",
    "forward_kinematics",
    "frame_poses",
    "point_jacobian",
    "end_effector_jacobian",
    "numeric_pose",
    "numeric_jacobian",
]


def _named(T: Transform, program: Program | None, hint: str) -> Transform:
    if program is None:
        return T
    R = sp.ImmutableMatrix(3, 3, [program.let(x, f"{hint}R") for x in T.R])
    p = sp.ImmutableMatrix(3, 1, [program.let(x, f"{hint}p") for x in T.p])
    return Transform(R, p)


def link_transforms(robot: Robot, q: Sequence | None = None) -> list[Transform]:
    """parent_T_i(q_i) for every link (symbolic q1..qn by default)."""
    if q is None:
        q = list(joint_symbols(robot.n)[0])
    return [link.joint_transform(qi) for link, qi in zip(robot.links, q, strict=True)]


def forward_kinematics(
    robot: Robot, q: Sequence | None = None, program: Program | None = None
) -> list[Transform]:
    """base_T_i for every link's body frame. With a `program`, entries are named intermediates."""
    poses: list[Transform] = []
    T = Transform.identity()
    for i, Ti in enumerate(link_transforms(robot, q)):
        T = _named(T @ Ti, program, f"T{i + 1}")
        poses.append(T)
    return poses


def frame_poses(robot: Robot, q: Sequence | None = None) -> list[Transform]:
    """base_T of each convention frame (e.g. standard-DH frame i at the distal end)."""
    return [T @ link.frame for T, link in zip(forward_kinematics(robot, q), robot.links, strict=True)]


def point_jacobian(
    robot: Robot,
    link: int,
    point: Sequence = (0, 0, 0),
    q: Sequence | None = None,
    poses: list[Transform] | None = None,
) -> sp.Matrix:
    """6 x n geometric Jacobian of `point` (body frame of link index `link`, 0-based), base frame."""
    n = robot.n
    k = link % n
    if poses is None:
        poses = forward_kinematics(robot, q)
    r = poses[k].apply(point)
    J = sp.zeros(6, n)
    for j in range(k + 1):
        z = poses[j].R * robot.links[j].axis
        if robot.links[j].joint == "revolute":
            J[:3, j] = z.cross(r - poses[j].p)
            J[3:, j] = z
        else:
            J[:3, j] = z
    return J


def end_effector_jacobian(robot: Robot, q: Sequence | None = None) -> sp.Matrix:
    """Jacobian of the last convention frame's origin (the DH end-effector frame)."""
    last = robot.links[-1]
    return point_jacobian(robot, -1, list(last.frame.p), q)


@lru_cache(maxsize=64)
def _pose_jacobian_function(robot: Robot, link: int, point: tuple):
    q = list(joint_symbols(robot.n)[0])
    r = robot.resolved()
    poses = forward_kinematics(r, q)
    T = poses[link % r.n].matrix()
    T[:3, 3] = poses[link % r.n].apply(point)
    J = point_jacobian(r, link, point, q, poses)
    return sp.lambdify([q, list(r.params)], [T, J], modules="numpy")


def _pose_and_jacobian(robot, q, link, point, params):
    values = robot.param_values(params) if robot.params else {}
    # a point may name parameters the file gives values for (the frame origin [l2, 0, 0])
    known = robot.value_map
    f = _pose_jacobian_function(robot, link, tuple(sp.sympify(x).xreplace(known) for x in point))
    T, J = f(np.asarray(q, dtype=float), [values[p] for p in robot.params])
    return np.asarray(T, dtype=float), np.asarray(J, dtype=float)


def numeric_pose(robot: Robot, q, link: int = -1, point=(0, 0, 0), params=None) -> np.ndarray:
    """4x4 pose (rotation of link `link`, position of `point`) in the base frame, as numbers."""
    return _pose_and_jacobian(robot, q, link, point, params)[0]


def numeric_jacobian(robot: Robot, q, link: int = -1, point=(0, 0, 0), params=None) -> np.ndarray:
    """6 x n geometric Jacobian of `point` on link `link`, base frame, as numbers."""
    return _pose_and_jacobian(robot, q, link, point, params)[1]
