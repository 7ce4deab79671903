"""The oracle's spatial kinematics (NumPy): joint poses, parent-to-child motion transforms,
motion subspaces and the spatial cross product, for a batch of N states.

Spatial vectors are Featherstone's (Rigid Body Dynamics Algorithms, 2008, ch. 2), in body
coordinates at the body origin, angular part first: motion v = [omega; v_O], force f = [n_O; f].
Shared by the numeric RNEA (symdyn.rnea) and its regressor (symdyn.oracle.regressor); like them it
reads only the numeric model (symdyn.oracle.inputs), never the symbolic derivation.
"""

from __future__ import annotations

import numpy as np

from .inputs import NumericModel, skew

__all__ = ["joint_poses", "motion_transforms", "subspaces", "crm", "mv"]


def joint_poses(mdl: NumericModel, q: np.ndarray):
    """Per body i: (E, r) with E = parent_R_i (N,3,3) and r = origin of body i in its parent
    (N,3), for the bodies' joint positions q (N, nb)."""
    out = []
    for i in range(mdl.nb):
        qi = q[:, i]
        if mdl.revolute[i]:
            k = mdl.axis[i]
            K = skew(k)
            c, s = np.cos(qi)[:, None, None], np.sin(qi)[:, None, None]
            rot = c * np.eye(3) + s * K + (1.0 - c) * np.outer(k, k)  # Rodrigues
            out.append((mdl.R0[i] @ rot, np.broadcast_to(mdl.p0[i], (len(qi), 3))))
        else:
            E = np.broadcast_to(mdl.R0[i], (len(qi), 3, 3))
            out.append((E, mdl.p0[i] + qi[:, None] * (mdl.R0[i] @ mdl.axis[i])))
    return out


def motion_transforms(poses) -> list[np.ndarray]:
    """i_X_lambda(i) = [[E^T, 0], [-E^T [r]x, E^T]]: parent motion vectors into body i coordinates."""
    xs = []
    for E, r in poses:
        Et = np.swapaxes(E, -1, -2)
        X = np.zeros((len(E), 6, 6))
        X[:, :3, :3] = Et
        X[:, 3:, 3:] = Et
        X[:, 3:, :3] = -Et @ skew(r)
        xs.append(X)
    return xs


def subspaces(mdl: NumericModel) -> np.ndarray:
    """Motion subspaces S_i (nb,6) in body coordinates: [axis; 0] revolute, [0; axis] prismatic."""
    S = np.zeros((mdl.nb, 6))
    S[mdl.revolute, :3] = mdl.axis[mdl.revolute]
    S[~mdl.revolute, 3:] = mdl.axis[~mdl.revolute]
    return S


def crm(v: np.ndarray) -> np.ndarray:
    """Spatial motion cross product matrix v x = [[w x, 0], [v_O x, w x]] for v (N,6)."""
    W, V = skew(v[:, :3]), skew(v[:, 3:])
    out = np.zeros((len(v), 6, 6))
    out[:, :3, :3] = W
    out[:, 3:, 3:] = W
    out[:, 3:, :3] = V
    return out


def mv(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """A x for stacks of matrices and vectors (..., 6, 6) x (..., 6)."""
    return np.einsum("...ij,...j->...i", A, x)
