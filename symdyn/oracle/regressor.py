"""The numeric regressor of the oracle: tau = Y(q, qd, qdd) pi, with NumPy only.

The Newton-Euler equations are linear in each body's 10 inertial parameters (Atkeson, An and
Hollerbach, "Estimation of inertial parameters of manipulator loads and links", 1986): in
Featherstone's spatial form (body frame i, vectors at its origin, motion v = [omega; v_O],
force f = [n_O; f]) the spatial inertia of body i is

    I_i(pi_i) = [[I_O, [h]x], [[h]x^T, m 1]],   h = m c,  I_O the tensor about the origin,

so its wrench f_i = I_i a_i + v_i x* I_i v_i = A(v_i, a_i) pi_i with A the 6 x 10 matrix whose
column k is B_k a_i + v_i x* B_k v_i for the basis inertia B_k = dI_i/dpi_k. Joint j's effort
collects the wrenches of its subtree, tau_j = S_j^T sum_{i in subtree(j)} j_X_i^* f_i, so row j
of Y holds S_j^T j_X_i^* A(v_i, a_i) in the columns of each body i that joint j supports; the
rotor and friction columns are qdd_j, qd_j and sign(qd_j) on joint j's own row (direction-dependent
Coulomb friction: [qd_j > 0] there and -[qd_j < 0] in joint j's fcn column after the 13 nb
others). The parameter order is symdyn.model.parameters (Pinocchio's `toDynamicParameters`, then
Ia, fv, fc).

As symdyn.rnea, this runs on the nb bodies at q_b = S q + o, qd_b = S qd, qdd_b = S qdd and
projects the rows with S^T (mimic joints), gravity entering as the base acceleration [0; -g].
It shares no code with the symbolic derivation: the spatial kinematics are the oracle's own
(symdyn.oracle.spatial) and the model comes from `symdyn.oracle.inputs`.
"""

from __future__ import annotations

import numpy as np

from .inputs import NumericModel, body_positions, body_rates, checked_inputs, project, skew
from .spatial import crm, joint_poses, motion_transforms, mv, subspaces

__all__ = ["regressor", "PER_BODY"]

#: columns per body: 10 inertial parameters, then Ia, fv, fc (symdyn.model.parameters)
PER_BODY = 13


def _basis() -> np.ndarray:
    """B_k (10, 6, 6) = dI/dpi_k: spatial inertia [[I_O, [h]x], [[h]x^T, m 1]] per parameter
    m, h_x, h_y, h_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz."""
    B = np.zeros((10, 6, 6))
    B[0, 3:, 3:] = np.eye(3)
    for k in range(3):
        h = skew(np.eye(3)[k])
        B[1 + k, :3, 3:] = h
        B[1 + k, 3:, :3] = h.T
    for k, (i, j) in enumerate(((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))):
        B[4 + k, :3, :3][i, j] = B[4 + k, :3, :3][j, i] = 1.0
    return B


_BASIS = _basis()


def _body_regressor(
    mdl: NumericModel, X: list[np.ndarray], qd_b: np.ndarray, qdd_b: np.ndarray
) -> np.ndarray:
    """Y_b (N, nb, 13 nb): the bodies' joint efforts tau_b = Y_b pi, in body coordinates."""
    N, nb = qd_b.shape
    S = subspaces(mdl)
    Y = np.zeros((N, nb, PER_BODY * nb + np.count_nonzero(mdl.asymmetric)))
    v, a = [], []
    for i in range(nb):
        p = mdl.parent[i]
        v_p = np.zeros((N, 6)) if p < 0 else v[p]
        a_p = np.concatenate([np.zeros((N, 3)), np.broadcast_to(-mdl.gravity, (N, 3))], 1) if p < 0 else a[p]
        vi = mv(X[i], v_p) + S[i] * qd_b[:, i, None]
        cross = crm(vi)
        ai = mv(X[i], a_p) + S[i] * qdd_b[:, i, None] + mv(cross, S[i] * qd_b[:, i, None])  # + v_i x S_i qd_i
        v.append(vi)
        a.append(ai)
        # A (N, 6, 10): column k = B_k a + v x* B_k v, with v x* = -(v x)^T
        force_cross = -np.swapaxes(cross, -1, -2)
        A = np.einsum("kij,nj->nik", _BASIS, ai) + np.einsum("nij,kjl,nl->nik", force_cross, _BASIS, vi)
        cols = slice(PER_BODY * i, PER_BODY * i + 10)
        j = i
        while True:  # carry body i's wrench down its support, S_j^T on every joint j it passes
            Y[:, j, cols] = np.einsum("i,nik->nk", S[j], A)
            if mdl.parent[j] < 0:
                break
            A = np.swapaxes(X[j], -1, -2) @ A
            j = mdl.parent[j]
        Y[:, i, PER_BODY * i + 10] = qdd_b[:, i]
        Y[:, i, PER_BODY * i + 11] = qd_b[:, i]
        if mdl.asymmetric[i]:  # H(qd) for fcp, -H(-qd) for fcn (after the 13 nb columns)
            Y[:, i, PER_BODY * i + 12] = qd_b[:, i] > 0
            Y[:, i, PER_BODY * nb + np.count_nonzero(mdl.asymmetric[:i])] = -1.0 * (qd_b[:, i] < 0)
        else:
            Y[:, i, PER_BODY * i + 12] = np.sign(qd_b[:, i])
    return Y


def regressor(robot, q, qd, qdd, params=None) -> np.ndarray:
    """The regressor Y(q, qd, qdd) with tau = Y pi (joint space, with friction and rotor inertia).

    pi is the standard parameter vector of `symdyn.standard_parameters` (13 per body: m, m c,
    the inertia about the body origin, Ia, fv, fc), so Y @ pi equals symdyn.rnea(robot, q, qd,
    qdd, params). Computed on the bodies (body frames, spatial vectors at each origin) and
    projected, Y = S^T Y_b, for mimic joints; see the module docstring for the recursion.

    Args:
        robot: a `symdyn.Robot` with n independent joints and nb bodies.
        q, qd, qdd: (n,) each, or (N, n) each for N states.
        params: the free parameters' values (only the kinematics need them: Y does not depend
            on the inertial and joint parameters).

    Returns:
        Y, (n, 13 nb) or (N, n, 13 nb).

    Raises:
        SymdynError: a vector of the wrong shape or not numeric, or bad parameter values.
    """
    mdl, (q, qd, qdd), single = checked_inputs("regressor", robot, params, ("q", q), ("qd", qd), ("qdd", qdd))
    X = motion_transforms(joint_poses(mdl, body_positions(mdl, q)))
    Y_b = _body_regressor(mdl, X, body_rates(mdl, qd), body_rates(mdl, qdd))
    Y = np.swapaxes(project(mdl, np.swapaxes(Y_b, 1, 2)), 1, 2)  # S^T Y_b, row by row
    return Y[0] if single else Y
