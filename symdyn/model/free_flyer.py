"""The free-flyer root joint of a floating-base robot: its coordinates, with Pinocchio's conventions.

A floating robot (`Robot.floating`) has its base link joined to the world by a free flyer, a
six-degree-of-freedom joint, ahead of its n joint coordinates:

    q  = [x, y, z, qx, qy, qz, qw, q_1 .. q_n]      (NQ = 7 + n)
    v  = [v_x, v_y, v_z, w_x, w_y, w_z, qd_1 .. qd_n] (NV = 6 + n)

(x, y, z) is the base frame's origin in the world frame and (qx, qy, qz, qw) the unit quaternion
of its orientation, world_R_base, with the scalar last; (v, w) are the linear velocity of the
base frame's origin and the angular velocity of the base, both in the base frame (the body twist,
Pinocchio's JointModelFreeFlyer). Accelerations are the time derivatives of v (the spatial
acceleration of the base in the base frame, then qdd), and the generalized forces are the wrench
on the base in the base frame, force then moment, then the joint torques: all of size NV.

The base's symbols carry a `_b` suffix, so that they never collide with joint symbols (q1 ..,
qd1 .., qdd1 ..) or with a robot file's parameters (which may not end in `_b` on a floating
robot: symdyn.parsers checks).

References: Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 4.2 (the free joint);
Pinocchio's JointModelFreeFlyer (its configuration and tangent vectors).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import sympy as sp

from .free_flyer_names import (
    BASE_ACCELERATION_NAMES,
    BASE_NAMES,
    BASE_POSITION_NAMES,
    BASE_VELOCITY_NAMES,
    BASE_WRENCH_NAMES,
    NQ_BASE,
    NV_BASE,
)

__all__ = [
    "BaseBody",
    "BASE_POSITION_NAMES",
    "BASE_VELOCITY_NAMES",
    "BASE_ACCELERATION_NAMES",
    "BASE_WRENCH_NAMES",
    "BASE_NAMES",
    "NQ_BASE",
    "NV_BASE",
    "base_symbols",
    "quaternion_rotation",
]


def base_symbols() -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """The column vectors (q_base (7), v_base (6), a_base (6)) of plain SymPy symbols."""
    return tuple(
        sp.Matrix([sp.Symbol(s) for s in names])
        for names in (BASE_POSITION_NAMES, BASE_VELOCITY_NAMES, BASE_ACCELERATION_NAMES)
    )


def _zero3() -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(sp.zeros(3, 1))


def _zero33() -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(sp.zeros(3, 3))


@dataclass(frozen=True)
class BaseBody:
    """The rigid body that the free flyer moves: the base link (and what is fixed to it).

    `mass`, `com` (3x1, base frame) and `inertia` (3x3 about the centre of mass, base-frame axes)
    enter the dynamics of a floating robot only (on a fixed base the base is the ground). `name`
    is the base link's name (the frame of the base).
    """

    name: str = "base"
    mass: sp.Expr = sp.S.Zero
    com: sp.ImmutableMatrix = field(default_factory=_zero3)
    inertia: sp.ImmutableMatrix = field(default_factory=_zero33)

    def subs(self, mapping: Mapping) -> BaseBody:
        x = dict(mapping)
        return BaseBody(
            self.name, sp.sympify(self.mass).xreplace(x), self.com.xreplace(x), self.inertia.xreplace(x)
        )


def quaternion_rotation(qx, qy, qz, qw) -> sp.Matrix:
    """world_R_base of the quaternion (qx, qy, qz, qw), scalar last (Hamilton's convention).

    R = 1 + s (qw [u]x + [u]x^2) with u = (qx, qy, qz) and s = 2 / |q|^2: the rotation of the
    normalised quaternion q / |q|, whatever the norm of q (for a unit quaternion s = 2, the usual
    polynomial form). Every floating-base function therefore reads the orientation of q / |q|;
    the zero quaternion has no orientation (s divides by zero: the results are not finite).
    """
    s = 2 / (qx**2 + qy**2 + qz**2 + qw**2)
    return sp.Matrix(
        [
            [1 - s * (qy**2 + qz**2), s * (qx * qy - qz * qw), s * (qx * qz + qy * qw)],
            [s * (qx * qy + qz * qw), 1 - s * (qx**2 + qz**2), s * (qy * qz - qx * qw)],
            [s * (qx * qz - qy * qw), s * (qy * qz + qx * qw), 1 - s * (qx**2 + qy**2)],
        ]
    )
