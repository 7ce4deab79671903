"""Forward kinematics and geometric Jacobians, symbolic (SymPy) and numeric.

All poses are body frames of the links expressed in the base frame, composed along
the path from the base: base_T_i = base_T_lambda(i) @ parent_T_i(q_i) (see
`symdyn.model.robot`; a chain gives parent_T_1(q_1) @ ... @ parent_T_i(q_i)). The
geometric Jacobian J = [Jv; Jw] (6 x n) of a point r fixed to link k maps joint
velocities to the point's linear velocity and the link's angular velocity, both
in the base frame. Per link j of the support of k (k and its ancestors):
    revolute j:  Jv_j = z_j x (r - o_j),  Jw_j = z_j
    prismatic j: Jv_j = z_j,              Jw_j = 0
with z_j the joint axis and o_j the body origin of link j, in the base frame; the other
links' columns are zero. Every function takes the n independent joint positions; a mimic
joint's position is q_j = multiplier q_i + offset (Robot.body_positions), and its column
adds to its coordinate's with the multiplier (J = J_b S).

References: Spong, Hutchinson, Vidyasagar, Robot Modeling and Control (2006), sec. 4.6
(derivation of the Jacobian); Craig, Introduction to Robotics (3rd ed., 2005), ch. 3 (forward
kinematics, frames composed link by link) and ch. 5 (Jacobians).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import NamedTuple

import numpy as np
import sympy as sp

from ..errors import SymdynError
from ..model.robot import Robot
from ..model.symbols import joint_symbols
from ..model.topology import support
from ..spatial.transform import Transform
from ..symbolic.program import Program

__all__ = [
    "link_transforms",
    "forward_kinematics",
    "frame_poses",
    "point_jacobian",
    "body_point_jacobian",
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


def _link_index(robot: Robot, link, where: str) -> int:
    """`link` as a 0-based index into robot.links (negative counts from the end)."""
    if isinstance(link, bool) or not isinstance(link, (int, np.integer)):
        raise SymdynError(f"{where}: link must be an integer index, got {link!r}")
    if not -robot.nb <= link < robot.nb:
        raise SymdynError(
            f"{where}: link {link} out of range: the robot has {robot.nb} links (0 .. {robot.nb - 1})"
        )
    return int(link) % robot.nb


def _point(point, where: str) -> tuple:
    try:
        out = tuple(sp.sympify(x) for x in point)
    except (TypeError, sp.SympifyError):
        raise SymdynError(f"{where}: point must be three numbers or expressions, got {point!r}") from None
    if len(out) != 3:
        raise SymdynError(f"{where}: point has {len(out)} entries, expected 3 (x, y, z in the link's frame)")
    return out


def link_transforms(robot: Robot, q: Sequence | None = None) -> list[Transform]:
    """parent_T_i(q_i) for every link (symbolic q1..qn by default).

    Args:
        robot: the model, nb links and n independent joints.
        q: n joint positions (symbols or numbers); None: the symbols q1..qn.

    Returns:
        nb transforms, link i's body frame in its parent's (the base for a link on the base).
    """
    if q is None:
        q = list(joint_symbols(robot.n)[0])
    if len(q) != robot.n:
        raise SymdynError(f"link_transforms: q has length {len(q)}, expected {robot.n} (one per joint)")
    return [link.joint_transform(qi) for link, qi in zip(robot.links, robot.body_positions(q), strict=True)]


def forward_kinematics(
    robot: Robot, q: Sequence | None = None, program: Program | None = None
) -> list[Transform]:
    """base_T_i for every link's body frame (Craig (2005), ch. 3), composed along the tree.

    Args:
        robot: the model, nb links and n independent joints.
        q: n joint positions; None: the symbols q1..qn.
        program: if given, every entry becomes a named intermediate of it.

    Returns:
        nb transforms, link i's body frame in the base frame.
    """
    poses: list[Transform] = []
    base = Transform.identity()
    for i, Ti in enumerate(link_transforms(robot, q)):
        p = robot.parents[i]
        poses.append(_named((base if p < 0 else poses[p]) @ Ti, program, f"T{i + 1}"))
    return poses


def frame_poses(robot: Robot, q: Sequence | None = None) -> list[Transform]:
    """base_T of each convention frame (e.g. standard-DH frame i at the distal end).

    Args and Returns as `forward_kinematics`, for the frames the robot file's convention names.
    """
    return [T @ link.frame for T, link in zip(forward_kinematics(robot, q), robot.links, strict=True)]


def point_jacobian(
    robot: Robot,
    link: int,
    point: Sequence = (0, 0, 0),
    q: Sequence | None = None,
    poses: Sequence[Transform] | None = None,
) -> sp.Matrix:
    """The geometric Jacobian of a point fixed to a link (Spong et al. (2006), sec. 4.6).

    Args:
        robot: the model, nb links and n independent joints.
        link: 0-based link index (negative counts from the end).
        point: the point in that link's body frame (3 entries).
        q: n joint positions; None: the symbols q1..qn.
        poses: `forward_kinematics(robot, q)`, to share it.

    Returns:
        J = [Jv; Jw] (6 x n): the point's linear velocity and the link's angular velocity
        per unit joint rate, both in the base frame; only the columns of the joints that
        support the link (the link and its ancestors) are nonzero.
    """
    k = _link_index(robot, link, "point_jacobian")
    if poses is None:
        poses = forward_kinematics(robot, q)
    r = poses[k].apply(_point(point, "point_jacobian"))
    axes = {j: (poses[j].R * robot.links[j].axis, poses[j].p) for j in support(robot.parents, k)}
    return _jacobian(robot, k, r, axes)


def _jacobian(robot: Robot, k: int, r: sp.Matrix, axes: dict[int, tuple]) -> sp.Matrix:
    """J = [Jv; Jw] (6 x n) of point r on link k from each supporting joint's (axis z_j, origin
    o_j), all in one frame: revolute z x (r - o), z; prismatic z, 0; mimic columns summed."""
    J = sp.zeros(6, robot.n)
    coordinates = robot.coordinates
    filled: set[int] = set()
    for j in reversed(support(robot.parents, k)):  # from the base out, as j = 1 .. k of a chain
        z, o = axes[j]
        revolute = robot.links[j].joint == "revolute"
        column = sp.Matrix.vstack(z.cross(r - o) if revolute else z, z if revolute else sp.zeros(3, 1))
        c = coordinates[j]
        if c.index in filled or c.multiplier != 1:  # a mimic joint adds to its coordinate: J = J_b S
            column = column * c.multiplier
            J[:, c.index] += column
        else:
            J[:, c.index] = column
        filled.add(c.index)
    return J


def body_point_jacobian(
    robot: Robot,
    link: int,
    point: Sequence = (0, 0, 0),
    q: Sequence | None = None,
    program: Program | None = None,
) -> sp.Matrix:
    """The Jacobian of a point fixed to a link, in that link's own body frame.

    The columns of `point_jacobian` rotated into link k's frame: J_k = blockdiag(R_k^T, R_k^T) J
    (Murray, Li, Sastry, A Mathematical Introduction to Robotic Manipulation (1994), sec. 4.2:
    the body Jacobian of a frame at the point). Built from the relative transforms k_T_j of the
    supporting links j, composed from k towards the base (k_T_lambda(j) = k_T_j j_T_lambda(j)),
    so a column depends only on the joints between j and k, never on the joints below j: the
    base pose, and with it the first joint, drops out of every product J_k^T X J_k.

    Args:
        robot: the model, nb links and n independent joints.
        link: 0-based link index (negative counts from the end).
        point: the point in that link's body frame (3 entries).
        q: n joint positions; None: the symbols q1..qn.
        program: if given, the entries of every k_T_j become named intermediates of it.

    Returns:
        6 x n: the point's linear velocity and the link's angular velocity per unit joint rate,
        in link k's body frame; only the supporting joints' columns are nonzero.
    """
    k = _link_index(robot, link, "body_point_jacobian")
    r = _vec3(_point(point, "body_point_jacobian"))
    local = link_transforms(robot, q)
    axes = {}
    T = Transform.identity()  # k_T_j, j walking from k to the base
    for j in support(robot.parents, k):
        axes[j] = (T.R * robot.links[j].axis, T.p)
        if robot.parents[j] >= 0:
            T = _named(T @ local[j].inverse(), program, f"T{k + 1}_{robot.parents[j] + 1}")
    return _jacobian(robot, k, r, axes)


def _vec3(x: tuple) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(3, 1, list(x))


def end_effector_jacobian(robot: Robot, q: Sequence | None = None) -> sp.Matrix:
    """Jacobian of the last convention frame's origin (the DH end-effector frame).

    Args:
        robot: the model, n links.
        q: n joint positions; None: the symbols q1..qn.

    Returns:
        6 x n, base frame (see `point_jacobian`).
    """
    last = robot.links[-1]
    return point_jacobian(robot, -1, list(last.frame.p), q)


class PoseJacobian(NamedTuple):
    """A link's pose (4x4, base frame) and the Jacobian (6 x n, base frame) of a point on it."""

    pose: np.ndarray
    jacobian: np.ndarray


@lru_cache(maxsize=16)
def _symbolic_poses(robot: Robot) -> tuple[tuple[sp.Symbol, ...], Robot, tuple[Transform, ...]]:
    """(q symbols, the resolved robot, its links' poses over q in the base frame): the forward
    kinematics that the pose and Jacobian functions of every link and point of `robot` share,
    computed once (the whole chain's products, n links, for each of them otherwise)."""
    q = tuple(joint_symbols(robot.n)[0])
    r = robot.resolved()
    return q, r, tuple(forward_kinematics(r, list(q)))


@lru_cache(maxsize=64)
def _pose_jacobian_function(robot: Robot, link: int, point: tuple):
    symbols, r, poses = _symbolic_poses(robot)
    q = list(symbols)
    T = poses[link].matrix()
    T[:3, 3] = poses[link].apply(point)
    J = point_jacobian(r, link, point, q, poses)
    return sp.lambdify([q, list(r.params)], [T, J], modules="numpy")


def _pose_and_jacobian(robot, q, link, point, params, where: str) -> PoseJacobian:
    if not isinstance(robot, Robot):
        raise SymdynError(f"{where}: robot must be a symdyn Robot, got {type(robot).__name__}")
    k = _link_index(robot, link, where)
    q = robot.joint_values(q, "q", where)
    values = robot.param_values(params, where)
    # a point may name parameters the file gives values for (the frame origin [l2, 0, 0])
    known = robot.value_map
    p = tuple(x.xreplace(known) for x in _point(point, where))
    unknown = sorted({str(s) for x in p for s in x.free_symbols} - {str(s) for s in robot.params})
    if unknown:
        raise SymdynError(f"{where}: point names unknown symbol(s) {', '.join(unknown)}")
    f = _pose_jacobian_function(robot, k, p)
    T, J = f(q, [values[s] for s in robot.params])
    return PoseJacobian(np.asarray(T, dtype=float), np.asarray(J, dtype=float))


def numeric_pose(robot: Robot, q, link: int = -1, point=(0, 0, 0), params=None) -> np.ndarray:
    """The pose of a link with a point on it, in the base frame, as numbers.

    Args:
        robot: the model, n links.
        q: n joint positions.
        link: 0-based link index (negative counts from the end).
        point: a point in that link's body frame (numbers, or expressions of the robot's
            parameters).
        params: values of the free parameters (a sequence in `robot.params` order or a
            name -> number map); None when there are none.

    Returns:
        4x4: the link's orientation (base frame) and the point's position (base frame).

    Raises:
        SymdynError: a q without n numbers, a link out of range, a point without three
            entries or naming unknown symbols, bad parameter values.
    """
    return _pose_and_jacobian(robot, q, link, point, params, "numeric_pose").pose


def numeric_jacobian(robot: Robot, q, link: int = -1, point=(0, 0, 0), params=None) -> np.ndarray:
    """The 6 x n geometric Jacobian of a point on a link, base frame, as numbers.

    Args and Raises as `numeric_pose`; Returns J = [Jv; Jw] (see `point_jacobian`).
    """
    return _pose_and_jacobian(robot, q, link, point, params, "numeric_jacobian").jacobian
