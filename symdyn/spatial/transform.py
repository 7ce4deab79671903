"""Rigid transforms (R, p) between link frames, symbolic (SymPy) throughout.

A `Transform` maps coordinates in a child frame B to its parent frame A:
x_A = R x_B + p, i.e. R = A_R_B and p is B's origin seen in A. Composition is
``A_T_C = A_T_B @ B_T_C``.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

__all__ = ["Transform", "rot_x", "rot_y", "rot_z", "rot_axis", "coordinate_axis", "rpy_matrix"]


def _vec(v) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(3, 1, [sp.sympify(x) for x in v])


def rot_x(a) -> sp.ImmutableMatrix:
    """Rotation about x by angle a (exact entries for multiples of pi/2)."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.ImmutableMatrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a) -> sp.ImmutableMatrix:
    """Rotation about y by angle a."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.ImmutableMatrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a) -> sp.ImmutableMatrix:
    """Rotation about z by angle a."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.ImmutableMatrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def coordinate_axis(axis) -> tuple[int, int] | None:
    """(k, sign) when the axis is sign * e_k (a coordinate axis, either way), else None."""
    ax = [sp.sympify(x) for x in axis]
    for k in range(3):
        if ax[k] in (1, -1) and all(ax[j] == 0 for j in range(3) if j != k):
            return k, int(ax[k])
    return None


def rot_axis(axis, a) -> sp.ImmutableMatrix:
    """Rotation by angle a about a unit axis (Rodrigues); coordinate axes give the plain forms."""
    coord = coordinate_axis(axis)
    if coord is not None:
        k, sign = coord
        return (rot_x, rot_y, rot_z)[k](a if sign == 1 else -a)
    ax = [sp.sympify(x) for x in axis]
    k = sp.Matrix(ax)
    K = sp.Matrix([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    c, s = sp.cos(a), sp.sin(a)
    return sp.ImmutableMatrix(sp.eye(3) * c + K * s + (1 - c) * (k * k.T))


def rpy_matrix(roll, pitch, yaw) -> sp.ImmutableMatrix:
    """URDF fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    return sp.ImmutableMatrix(rot_z(yaw) * rot_y(pitch) * rot_x(roll))


@dataclass(frozen=True)
class Transform:
    """A rigid transform x_parent = R x_child + p (SymPy entries)."""

    R: sp.ImmutableMatrix
    p: sp.ImmutableMatrix

    @staticmethod
    def identity() -> Transform:
        return Transform(sp.ImmutableMatrix(sp.eye(3)), sp.ImmutableMatrix(sp.zeros(3, 1)))

    @staticmethod
    def from_rotation(R) -> Transform:
        return Transform(sp.ImmutableMatrix(R), sp.ImmutableMatrix(sp.zeros(3, 1)))

    @staticmethod
    def from_translation(p) -> Transform:
        return Transform(sp.ImmutableMatrix(sp.eye(3)), _vec(p))

    @staticmethod
    def rx(a) -> Transform:
        return Transform.from_rotation(rot_x(a))

    @staticmethod
    def rz(a) -> Transform:
        return Transform.from_rotation(rot_z(a))

    @staticmethod
    def tx(d) -> Transform:
        return Transform.from_translation((d, 0, 0))

    @staticmethod
    def tz(d) -> Transform:
        return Transform.from_translation((0, 0, d))

    def __matmul__(self, other: Transform) -> Transform:
        R = sp.ImmutableMatrix(self.R * other.R)
        p = sp.ImmutableMatrix(self.R * other.p + self.p)
        return Transform(R, p)

    def inverse(self) -> Transform:
        Rt = self.R.T
        return Transform(sp.ImmutableMatrix(Rt), sp.ImmutableMatrix(-(Rt * self.p)))

    def apply(self, x) -> sp.ImmutableMatrix:
        """Map a point given in the child frame to the parent frame."""
        return sp.ImmutableMatrix(self.R * _vec(x) + self.p)

    def matrix(self) -> sp.Matrix:
        """The 4x4 homogeneous matrix."""
        T = sp.eye(4)
        T[:3, :3] = self.R
        T[:3, 3] = self.p
        return T

    def subs(self, mapping) -> Transform:
        return Transform(self.R.xreplace(mapping), self.p.xreplace(mapping))

    def is_identity(self) -> bool:
        return sp.eye(3) == self.R and self.p == sp.zeros(3, 1)
