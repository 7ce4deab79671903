"""MuJoCo's compiled doubles as the numbers of the model: lengths and masses, and rotations.

The compiled model (mujoco.MjModel) holds every pose as a position and a unit quaternion
(w, x, y, z), whatever the file wrote (euler angles in degrees, axisangle, xyaxes, zaxis, a
fullinertia's principal axes). Numbers follow the rules of the URDF loader
(symdyn.parsers.urdf_elements): an integer value becomes an exact Integer, any other double the
Float of that double. A rotation is turned into roll, pitch and yaw (R = Rz(yaw) Ry(pitch)
Rx(roll), the URDF's convention) and each angle goes through symdyn.model.angles.snap_angle: within
1e-9 rad of a multiple of pi/2 it becomes that exact multiple, so that a right angle written as
euler="90 0 0" (compiled to the quaternion (0.7071067811865476, 0.7071067811865475, 0, 0)) gives
a rotation matrix of exact 0 and +-1.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from ..model.angles import snap_angle
from ..spatial.transform import Transform, rpy_matrix
from .urdf_elements import numeric

__all__ = ["number", "vector", "quat_rotation", "pose"]


def number(x: float) -> sp.Expr:
    """A compiled double as a SymPy number: an exact Integer when integral (below 2**53), else a Float."""
    x = float(x)
    if x == int(x) and abs(x) < 2**53:
        return sp.Integer(int(x))
    return sp.Float(x)


def vector(values) -> sp.ImmutableMatrix:
    """A 3-vector of compiled doubles as a column of SymPy numbers."""
    return sp.ImmutableMatrix(3, 1, [number(v) for v in values])


def _quat_matrix(quat) -> np.ndarray:
    """The rotation matrix of a quaternion (w, x, y, z), normalised first."""
    w, x, y, z = np.asarray(quat, dtype=float) / np.linalg.norm(quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _rpy(R: np.ndarray) -> tuple[float, float, float]:
    """Roll, pitch, yaw with R = Rz(yaw) Ry(pitch) Rx(roll); at pitch = +-pi/2 (gimbal lock) yaw = 0."""
    cos_pitch = math.hypot(R[0, 0], R[1, 0])
    pitch = math.atan2(-R[2, 0], cos_pitch)
    if cos_pitch > 1e-9:
        return math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0])
    return math.atan2(-R[1, 2], R[1, 1]), pitch, 0.0


def quat_rotation(quat, **where) -> sp.ImmutableMatrix:
    """The rotation of a compiled quaternion (w, x, y, z), its roll, pitch and yaw snapped to exact
    multiples of pi/2 within 1e-9 rad (`where`: file, link_name, field for a warning)."""
    if tuple(float(v) for v in quat) == (1.0, 0.0, 0.0, 0.0):
        return sp.ImmutableMatrix(sp.eye(3))
    angles = [
        snap_angle(sp.Float(a), angle=name, expressions=False, **where)
        for a, name in zip(_rpy(_quat_matrix(quat)), ("roll", "pitch", "yaw"), strict=True)
    ]
    return rpy_matrix(*angles).applyfunc(numeric)


def pose(pos, quat, **where) -> Transform:
    """The transform of a compiled position and quaternion (the child frame in the parent frame)."""
    return Transform(quat_rotation(quat, **where), vector(pos))
