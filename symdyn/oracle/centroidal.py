"""The numeric oracle's centroidal quantities, NumPy only: total mass, centre of mass, the
centroidal momentum matrix A_g and its drift Adot_g v, for a floating or a fixed base.

Independent of the symbolic code (symdyn.algorithms.centroidal, which works with composite
moments in the base frame): here every body is moved in the world, one state at a time, and
the momentum is summed body by body,

    h_g = sum_i [m_i v_ci; (c_i - c) x m_i v_ci + I_i w_i]          (world axes, about c)

with v_ci, w_i the world velocities of body i's centre of mass and its angular velocity. h_g is
linear in v, so A_g's column k is h_g at v = e_k. The drift is the rate of h_g at vdot = 0:

    Adot_g v = sum_i [m_i a_ci; (c_i - c) x m_i a_ci + w_i x I_i w_i + I_i wd_i]

with the classical accelerations a_ci and angular accelerations wd_i of the bodies when the
base's body twist is constant (its origin accelerates by w x v) and qdd = 0.

The configuration and velocity are symdyn.model.free_flyer's on a floating base (q: NQ =
7 + n, the quaternion normalised here; v: NV = 6 + n), the joints' on a fixed one (n and n);
the bodies are the links and, on a floating base, the base body (Robot.base_body).
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from ..errors import SymdynError
from ..model.quaternion_norm import check_quaternions
from .frames import frame_state
from .inputs import body_positions, body_rates, numeric_model, skew
from .rnea import mass_matrix
from .spatial import joint_poses

__all__ = [
    "CentroidalState",
    "centroidal",
    "quaternion_matrix",
    "floating_frame_jacobian",
    "generalized_jacobian",
]


class CentroidalState(NamedTuple):
    """mass (float), com (3,), com_jacobian (3, NV), Ag (6, NV), drift (6,): world frame."""

    mass: float
    com: np.ndarray
    com_jacobian: np.ndarray
    Ag: np.ndarray
    drift: np.ndarray


def quaternion_matrix(quat: np.ndarray) -> np.ndarray:
    """world_R_base of the quaternion (qx, qy, qz, qw), normalised first (scalar last)."""
    x, y, z, w = np.asarray(quat, dtype=float) / np.linalg.norm(quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _vector(robot, value, size: int, name: str) -> np.ndarray:
    try:
        x = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SymdynError(f"centroidal: robot '{robot.name}': {name} is not a vector of numbers") from None
    if x.shape != (size,) or not np.all(np.isfinite(x)):
        raise SymdynError(
            f"centroidal: robot '{robot.name}': {name} must be {size} finite numbers, got shape {x.shape}"
        )
    return x


class _Bodies:
    """World poses, inertias and motions of every body of one configuration."""

    def __init__(self, robot, q: np.ndarray, params) -> None:
        mdl = numeric_model(robot, params)
        self.mdl = mdl
        n = mdl.n
        if robot.floating:
            self.R0, self.p0 = quaternion_matrix(q[3:7]), q[:3]
            joints = q[7:]
        else:
            self.R0, self.p0 = mdl.base_R, mdl.base_p
            joints = q
        self.joints = joints
        assert len(joints) == n
        qb = body_positions(mdl, joints[None])
        self.R, self.o = [], []
        for i, (E, r) in enumerate(joint_poses(mdl, qb)):
            p = mdl.parent[i]
            Rp, op = (self.R[p], self.o[p]) if p >= 0 else (self.R0, self.p0)
            self.R.append(Rp @ E[0])
            self.o.append(op + Rp @ r[0])
        self.axis = [self.R[i] @ mdl.axis[i] for i in range(mdl.nb)]
        self.mass = list(mdl.mass)
        self.c = [self.o[i] + self.R[i] @ mdl.com[i] for i in range(mdl.nb)]
        self.I = [self.R[i] @ mdl.inertia[i] @ self.R[i].T for i in range(mdl.nb)]
        self.origin = list(self.o)
        if robot.floating:
            b = robot.numeric(params).base_body
            com = np.array(b.com, dtype=float).ravel()
            self.mass.append(float(b.mass))
            self.c.append(self.p0 + self.R0 @ com)
            self.I.append(self.R0 @ np.array(b.inertia, dtype=float) @ self.R0.T)
            self.origin.append(self.p0)
        self.total = float(sum(self.mass))
        self.com = sum(m * c for m, c in zip(self.mass, self.c, strict=True)) / self.total

    def motions(self, robot, V: np.ndarray):
        """(w, wd, v_O, a_O) of every body (the base body last when floating), world axes, each
        (3, K) for the K velocities V (NV, K): the velocities are linear in V, the accelerations
        mean something for K = 1 only."""
        mdl = self.mdl
        K = V.shape[1]
        if robot.floating:
            w0, v0 = self.R0 @ V[3:6], self.R0 @ V[:3]
            root = (w0, np.zeros((3, K)), v0, _cross(w0, v0))
            rates = body_rates(mdl, V[6:].T).T
        else:
            root = (np.zeros((3, K)),) * 4
            rates = body_rates(mdl, V.T).T
        out = []
        for i in range(mdl.nb):
            p = mdl.parent[i]
            w, wd, vo, a = out[p] if p >= 0 else root
            d = (self.o[i] - (self.o[p] if p >= 0 else self.p0))[:, None]
            zq = self.axis[i][:, None] * rates[i]
            vo, a = vo + _cross(w, d), a + _cross(wd, d) + _cross(w, _cross(w, d))
            if mdl.revolute[i]:
                w, wd = w + zq, wd + _cross(w, zq)
            else:
                vo, a = vo + zq, a + 2 * _cross(w, zq)
            out.append((w, wd, vo, a))
        return out + [root] if robot.floating else out

    def momentum(self, robot, V: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(h_g, its rate at vdot = 0), (6, K) each, for the K velocities V (module docstring)."""
        K = V.shape[1]
        h, dh = np.zeros((6, K)), np.zeros((6, K))
        for m, c, I, o, (w, wd, vo, a) in zip(
            self.mass, self.c, self.I, self.origin, self.motions(robot, V), strict=True
        ):
            r = (c - o)[:, None]
            vc = vo + _cross(w, r)
            ac = a + _cross(wd, r) + _cross(w, _cross(w, r))
            arm = (c - self.com)[:, None]
            h += np.r_[m * vc, _cross(arm, m * vc) + I @ w]
            dh += np.r_[m * ac, _cross(arm, m * ac) + _cross(w, I @ w) + I @ wd]
        return h, dh


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Column-wise a x b of (3, K) arrays (either may be (3, 1))."""
    return np.cross(a, b, axis=0)


def centroidal(robot, q, v=None, params=None) -> CentroidalState:
    """Total mass, centre of mass, its Jacobian, A_g and Adot_g v at (q, v) (module docstring).

    Raises:
        SymdynError: q or v of the wrong size or not finite, bad parameter values.
    """
    q = _vector(robot, q, robot.nq, "q")
    v = np.zeros(robot.nv) if v is None else _vector(robot, v, robot.nv, "v")
    if robot.floating and np.linalg.norm(q[3:7]) == 0:
        raise SymdynError(f"centroidal: robot '{robot.name}': the base quaternion q[3:7] is zero")
    if robot.floating:
        check_quaternions(q, f"centroidal: robot '{robot.name}': q")
    bodies = _Bodies(robot, q, params)
    Ag = bodies.momentum(robot, np.eye(robot.nv))[0]
    drift = bodies.momentum(robot, v[:, None])[1][:, 0]
    return CentroidalState(bodies.total, bodies.com, Ag[:3] / bodies.total, Ag, drift)


def floating_frame_jacobian(robot, q, frame: str, params=None) -> tuple[np.ndarray, np.ndarray]:
    """(world_T_F (4 x 4), J (6 x NV)) of a floating robot's frame: J world-aligned at F's origin,
    rows v then w, the base's columns [R, -R [r]x; 0, R] (r = base_p_F) then blockdiag(R, R) times
    the fixed-base Jacobian of the joints (symdyn.oracle.frames on the robot with its base fixed)."""
    q = _vector(robot, q, robot.nq, "q")
    fixed = dataclasses.replace(robot, floating=False)
    base_T_F = frame_state(fixed, frame, q[7:], None, params)
    R = quaternion_matrix(q[3:7])
    r = base_T_F.pose[:3, 3]
    world_T_base = np.eye(4)
    world_T_base[:3, :3], world_T_base[:3, 3] = R, q[:3]
    J = np.zeros((6, robot.nv))
    J[:3, :3], J[:3, 3:6], J[3:, 3:6] = R, -R @ skew(r), R
    J[:3, 6:], J[3:, 6:] = R @ base_T_F.jacobian[:3], R @ base_T_F.jacobian[3:]
    return world_T_base @ base_T_F.pose, J


def generalized_jacobian(robot, q, frame: str, params=None) -> np.ndarray:
    """J* = J_m - J_b H_b^-1 H_bm (6 x n) of a floating robot's frame (Umetani and Yoshida, 1989):
    the frame's world-aligned velocity from the joint rates alone when the robot's momentum is zero.

    H_b, H_bm are the base rows of M (the momentum of the whole robot in the base frame is
    H_b v_base + H_bm qd, zero: v_base = -H_b^-1 H_bm qd), J_b, J_m the base's and the joints'
    columns of floating_frame_jacobian.
    """
    M = mass_matrix(robot, q, params)
    J = floating_frame_jacobian(robot, q, frame, params)[1]
    return J[:, 6:] - J[:, :6] @ np.linalg.solve(M[:6, :6], M[:6, 6:])
