"""The numeric oracle's frame kinematics: pose, Jacobians, drift and centre of mass, NumPy only.

Independent of the symbolic code (symdyn.algorithms.frame_kinematics): it reads only the
numeric model (symdyn.oracle.inputs) and works in spatial algebra, body coordinates
(Featherstone, Rigid Body Dynamics Algorithms (2008), ch. 2-3), one state at a time:

    v_i = i_X_p v_p + S_i qd_i,   a_i = i_X_p a_p + v_i x S_i qd_i     (qdd = 0, base at rest)

with spatial vectors [w; v_O] in body i's coordinates. Link k's Jacobian in its own coordinates
has the columns k_X_j S_j of its supporting joints j; a frame F on link k takes
F_X_k = (k_T_F)^-1 as a motion transform. The classical acceleration of F's origin is the
spatial one plus w x v (Featherstone (2008), sec. 2.11). Results are in Pinocchio's conventions:
rows v_x v_y v_z w_x w_y w_z, world-aligned ("world") or in F's axes ("local"); the world is the
base frame placed at Robot.base. Mimic joints: J = J_b S (the n independent coordinates).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..errors import SymdynError
from .inputs import NumericModel, body_positions, body_rates, checked_inputs, skew
from .spatial import joint_poses, subspaces

__all__ = ["FrameState", "frame_state", "placed_frame_state", "center_of_mass"]


class FrameState(NamedTuple):
    """A frame's pose (4 x 4, world), Jacobians (6 x n: world-aligned, local) and drift (6,)."""

    pose: np.ndarray
    jacobian: np.ndarray
    jacobian_local: np.ndarray
    drift: np.ndarray


def _motion(T: np.ndarray) -> np.ndarray:
    """a_X_b of a_T_b = (R, p): [[R, 0], [p x R, R]] on [w; v_O]."""
    R, p = T[:3, :3], T[:3, 3]
    X = np.zeros((6, 6))
    X[:3, :3] = X[3:, 3:] = R
    X[3:, :3] = skew(p) @ R
    return X


def _homogeneous(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


class _Kinematics:
    """Body poses (world), spatial velocities and accelerations (body coordinates) of one state."""

    def __init__(self, mdl: NumericModel, q: np.ndarray, qd: np.ndarray) -> None:
        self.mdl = mdl
        qb, qdb = body_positions(mdl, q[None])[0], body_rates(mdl, qd[None])[0]
        S = subspaces(mdl)
        self.S = S
        base = _homogeneous(mdl.base_R, mdl.base_p)
        self.T, self.v, self.a = [], [], []
        for i, (E, r) in enumerate(joint_poses(mdl, qb[None])):
            local = _homogeneous(E[0], r[0])
            p = mdl.parent[i]
            X = _motion(np.linalg.inv(local))  # i_X_p
            v_p, a_p = (self.v[p], self.a[p]) if p >= 0 else (np.zeros(6), np.zeros(6))
            v = X @ v_p + S[i] * qdb[i]
            w, lin = v[:3], v[3:]
            s = S[i] * qdb[i]
            cross = np.r_[np.cross(w, s[:3]), np.cross(lin, s[:3]) + np.cross(w, s[3:])]  # v x s
            self.T.append((self.T[p] if p >= 0 else base) @ local)
            self.v.append(v)
            self.a.append(X @ a_p + cross)
        self.base = base

    def frame(self, k: int, placement: np.ndarray) -> FrameState:
        mdl, n = self.mdl, self.mdl.n
        Tk = self.base if k < 0 else self.T[k]
        pose = Tk @ placement
        J = np.zeros((6, mdl.nb))
        v, a = np.zeros(6), np.zeros(6)
        if k >= 0:
            j = k
            while j >= 0:
                J[:, j] = _motion(np.linalg.inv(Tk) @ self.T[j]) @ self.S[j]
                j = mdl.parent[j]
            v, a = self.v[k], self.a[k]
        XF = _motion(np.linalg.inv(placement))
        JF = (XF @ J @ mdl.selection)[[3, 4, 5, 0, 1, 2]]
        vF, aF = XF @ v, XF @ a
        drift_local = np.r_[aF[3:] + np.cross(vF[:3], vF[3:]), aF[:3]]
        R = np.kron(np.eye(2), pose[:3, :3])
        assert JF.shape == (6, n)
        return FrameState(pose, R @ JF, JF, R @ drift_local)


def _state(where: str, robot, q, qd, params):
    qd = np.zeros(np.shape(q)) if qd is None else qd
    mdl, (q, qd), single = checked_inputs(where, robot, params, ("q", q), ("qd", qd))
    if not single:
        raise SymdynError(f"{where}: give one state (q of shape (n,))")
    return mdl, _Kinematics(mdl, q[0], qd[0])


def frame_state(robot, frame: str, q, qd=None, params=None) -> FrameState:
    """Pose, Jacobians and drift Jdot qd of the frame named `frame` at (q, qd) (module docstring).

    Raises:
        SymdynError: an unknown frame, bad vectors or parameter values.
    """
    mdl, kin = _state("frame_state", robot, q, qd, params)
    if frame not in mdl.frame_names:
        robot.frame(frame, "frame_state")  # raises, naming the near matches
    f = mdl.frame_names.index(frame)
    return kin.frame(int(mdl.frame_link[f]), _homogeneous(mdl.frame_R[f], mdl.frame_p[f]))


def placed_frame_state(robot, link: int, placement: np.ndarray, q, qd=None, params=None) -> FrameState:
    """`frame_state` of a frame given by its link (-1: the base) and placement k_T_F (4 x 4, in
    the link's body frame): a loop's closure frame (symdyn.model.loops)."""
    _, kin = _state("placed_frame_state", robot, q, qd, params)
    return kin.frame(int(link), np.asarray(placement, dtype=float))


def center_of_mass(robot, q, qd=None, params=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(c (3,), Jc (3, n), Jc_dot qd (3,)): the centre of mass, its Jacobian and drift, world."""
    mdl, kin = _state("center_of_mass", robot, q, qd, params)
    total = mdl.mass.sum()
    c, Jc, drift = np.zeros(3), np.zeros((3, mdl.n)), np.zeros(3)
    for i, m in enumerate(mdl.mass):
        s = kin.frame(i, _homogeneous(np.eye(3), mdl.com[i]))
        c += m * s.pose[:3, 3]
        Jc += m * s.jacobian[:3]
        drift += m * s.drift[:3]
    return c / total, Jc / total, drift / total
