"""The oracle's two recursions over the bodies, shared by the fixed and the floating base: the
spatial RNEA and the CRBA on the tree (NumPy, a batch of N states).

Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 5.3 and 6.2; spatial vectors in body
coordinates at the body origin, angular part first (symdyn.oracle.spatial). The base is body -1:
its motion (v_0, a_0) is given (zero and [0; -g] on a fixed base; the free flyer's twist and
acceleration, gravity included, on a floating one), and what the bodies push on it comes back:
the wrench f_0 of the RNEA and the composite inertia and columns of the CRBA.
"""

from __future__ import annotations

import numpy as np

from .inputs import NumericModel
from .spatial import crm, joint_poses, motion_transforms, mv, subspaces

__all__ = ["body_rnea", "body_crba", "joint_friction"]


def body_rnea(
    mdl: NumericModel, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, base_v: np.ndarray, base_a: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Rigid-body efforts of the bodies' joints (N, nb) and the wrench the bodies exert on the base
    (N, 6), in the base frame [n_0; f_0], by the spatial RNEA on the tree.

    Outward: v_i = X_i v_p + S_i qd_i, a_i = X_i a_p + S_i qdd_i + v_i x S_i qd_i, with
    (v_p, a_p) = (base_v, base_a) (N, 6) for a body on the base; f_i = I_i a_i + v_i x* I_i v_i.
    Inward: tau_i = S_i^T f_i, f_p += X_i^T f_i (f_0 for p = -1). Bodies' joint positions,
    velocities and accelerations q, qd, qdd: (N, nb) each.
    """
    N = len(q)
    X = motion_transforms(joint_poses(mdl, q))
    S = subspaces(mdl)
    vs: list[np.ndarray] = []
    accs: list[np.ndarray] = []
    forces = []
    for i in range(mdl.nb):
        p = mdl.parent[i]
        v_p, a_p = (base_v, base_a) if p < 0 else (vs[p], accs[p])
        v = mv(X[i], v_p) + S[i] * qd[:, i, None]
        vx = crm(v)
        a = mv(X[i], a_p) + S[i] * qdd[:, i, None] + mv(vx, S[i]) * qd[:, i, None]
        vs.append(v)
        accs.append(a)
        Iv = mv(mdl.spatial_inertia[i], v)
        # f = I a + v x* (I v), with v x* = -(v x)^T the force cross product.
        forces.append(mv(mdl.spatial_inertia[i], a) - mv(np.swapaxes(vx, -1, -2), Iv))
    tau = np.zeros((N, mdl.nb))
    base_f = np.zeros((N, 6))
    for i in reversed(range(mdl.nb)):  # every child's force is in by now: children come later
        tau[:, i] = forces[i] @ S[i]
        p = mdl.parent[i]
        pushed = mv(np.swapaxes(X[i], -1, -2), forces[i])
        if p >= 0:
            forces[p] = forces[p] + pushed
        else:
            base_f = base_f + pushed
    return tau, base_f


def body_crba(mdl: NumericModel, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The bodies' mass matrix M_b (N, nb, nb) by the CRBA, with what the base sees: the columns
    F_0 (N, 6, nb) of each body's joint carried down to the base frame (X^T ... Ic_i S_i: the
    base-joint block of a floating M) and the composite inertia (N, 6, 6) of all the bodies in the
    base frame (without the base body's own). q: the bodies' joint positions (N, nb).

    Ic_lambda(i) += X_i^T Ic_i X_i (inward); F = Ic_i S_i, M_ii = S_i^T F, M_ij = S_j^T F for each
    ancestor j with F <- X_k^T F down the path; the rest is zero (different branches).
    """
    N = len(q)
    X = motion_transforms(joint_poses(mdl, q))
    S = subspaces(mdl)
    Ic = [np.broadcast_to(mdl.spatial_inertia[i], (N, 6, 6)).copy() for i in range(mdl.nb)]
    M = np.zeros((N, mdl.nb, mdl.nb))
    F0 = np.zeros((N, 6, mdl.nb))
    Ic0 = np.zeros((N, 6, 6))
    for i in reversed(range(mdl.nb)):  # Ic[i] is complete: its children come after it
        p = mdl.parent[i]
        carried = np.swapaxes(X[i], -1, -2) @ Ic[i] @ X[i]
        if p >= 0:
            Ic[p] += carried
        else:
            Ic0 += carried
        F = Ic[i] @ S[i]
        M[:, i, i] = F @ S[i]
        j = i
        while mdl.parent[j] >= 0:
            F = mv(np.swapaxes(X[j], -1, -2), F)
            j = mdl.parent[j]
            M[:, i, j] = M[:, j, i] = F @ S[j]
        F0[:, :, i] = mv(np.swapaxes(X[j], -1, -2), F)
    return M, F0, Ic0


def joint_friction(mdl: NumericModel, qd_b: np.ndarray) -> np.ndarray:
    """The bodies' friction efforts at their rates qd_b (N, nb): viscous qd + coulomb [qd > 0]
    - coulomb_minus [qd < 0] (= coulomb sign(qd) when the two magnitudes are the same)."""
    return mdl.viscous * qd_b + mdl.coulomb * (qd_b > 0) - mdl.coulomb_minus * (qd_b < 0)
