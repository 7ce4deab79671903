"""The independent numeric oracle: rigid-body dynamics of a `Robot` with NumPy only.

Every symbolic derivation and every generated function is judged against this
module, so it shares no code with them: it reads the `Robot` model, converts it
once to NumPy arrays (`numeric_model`, cached per robot and parameter values, in
symdyn.rnea_inputs with the checks of every argument) and never calls SymPy while
evaluating. It also uses a different formulation
from the lecture's link-frame recursion (slides 14-15): Featherstone's
spatial-vector algorithms in body coordinates, with motion vectors
v = [omega; v_O] and force vectors f = [n_O; f] (angular part first, both
taken at the body-frame origin O and expressed in body-frame axes):

* inverse dynamics: the recursive Newton-Euler algorithm (RNEA) on spatial
  vectors, gravity entered as a fictitious base acceleration a_0 = [0; -g];
* mass matrix: the composite-rigid-body algorithm (CRBA);
* energies and kinematics: poses composed in the base frame.

Body i moves relative to body i-1 by parent_T_i(q_i) = placement @ Rot(axis, q_i)
(revolute, motion subspace S_i = [axis; 0]) or placement @ Trans(axis q_i)
(prismatic, S_i = [0; axis]). Every public function accepts a single state
(vectors of length n) or a batch (arrays of shape (N, n)).
"""

from __future__ import annotations

import sys
import types

import numpy as np

from .rnea_inputs import NumericModel, checked_inputs, numeric_model, skew

__all__ = [
    "NumericModel",
    "numeric_model",
    "rnea",
    "mass_matrix",
    "gravity_torque",
    "bias_torque",
    "friction_torque",
    "forward_dynamics",
    "kinetic_energy",
    "potential_energy",
    "forward_kinematics",
    "link_com_positions",
]


def _out(a: np.ndarray, single: bool) -> np.ndarray:
    return a[0] if single else a


def _joint_poses(mdl: NumericModel, q: np.ndarray):
    """Per joint i: (E, r) with E = parent_R_i (N,3,3) and r = origin of body i in parent (N,3)."""
    out = []
    for i in range(mdl.n):
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


def _motion_transforms(poses) -> list[np.ndarray]:
    """i_X_{i-1} = [[E^T, 0], [-E^T [r]x, E^T]]: parent motion vectors into body i coordinates."""
    xs = []
    for E, r in poses:
        Et = np.swapaxes(E, -1, -2)
        X = np.zeros((len(E), 6, 6))
        X[:, :3, :3] = Et
        X[:, 3:, 3:] = Et
        X[:, 3:, :3] = -Et @ skew(r)
        xs.append(X)
    return xs


def _subspaces(mdl: NumericModel) -> np.ndarray:
    """Motion subspaces S_i (n,6) in body coordinates: [axis; 0] revolute, [0; axis] prismatic."""
    S = np.zeros((mdl.n, 6))
    S[mdl.revolute, :3] = mdl.axis[mdl.revolute]
    S[~mdl.revolute, 3:] = mdl.axis[~mdl.revolute]
    return S


def _crm(v: np.ndarray) -> np.ndarray:
    """Spatial motion cross product matrix v x = [[w x, 0], [v_O x, w x]] for v (N,6)."""
    W, V = skew(v[:, :3]), skew(v[:, 3:])
    out = np.zeros((len(v), 6, 6))
    out[:, :3, :3] = W
    out[:, 3:, 3:] = W
    out[:, 3:, :3] = V
    return out


def _mv(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("...ij,...j->...i", A, x)


def _rnea(mdl, q, qd, qdd, g_on: bool, f_on: bool) -> np.ndarray:
    """Spatial RNEA on a batch (all arguments (N, n)); see `rnea`."""
    N, n = q.shape
    X = _motion_transforms(_joint_poses(mdl, q))
    S = _subspaces(mdl)
    v = np.zeros((N, 6))
    a = np.zeros((N, 6))
    if g_on:
        a[:, 3:] = -mdl.gravity  # fictitious base acceleration a_0 = [0; -g]
    forces = []
    for i in range(n):
        v = _mv(X[i], v) + S[i] * qd[:, i, None]
        vx = _crm(v)
        a = _mv(X[i], a) + S[i] * qdd[:, i, None] + _mv(vx, S[i]) * qd[:, i, None]
        Iv = _mv(mdl.spatial_inertia[i], v)
        # f = I a + v x* (I v), with v x* = -(v x)^T the force cross product.
        forces.append(_mv(mdl.spatial_inertia[i], a) - _mv(np.swapaxes(vx, -1, -2), Iv))
    tau = np.zeros((N, n))
    for i in reversed(range(n)):
        tau[:, i] = forces[i] @ S[i]
        if i > 0:
            forces[i - 1] = forces[i - 1] + _mv(np.swapaxes(X[i], -1, -2), forces[i])
    tau += mdl.reflected * qdd
    if f_on:
        tau += mdl.viscous * qd + mdl.coulomb * np.sign(qd)
    return tau


def rnea(robot, q, qd, qdd, params=None, *, gravity=True, friction=True) -> np.ndarray:
    """Inverse dynamics tau = M(q) qdd + V(q, qd) + G(q) + F(qd), by the spatial RNEA.

    Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 5.3; the lecture's 3-vector form
    is R. Grupen, "Dynamics" (2015), slides 14-15 (symdyn.algorithms.newton_euler).
    Body frames, spatial vectors at each body origin. Outward: v_i = X_i v_{i-1} + S_i qd_i,
    a_i = X_i a_{i-1} + S_i qdd_i + v_i x S_i qd_i, from v_0 = 0 and a_0 = [0; -g] (gravity
    in the base frame; a_0 = 0 with gravity=False); body force f_i = I_i a_i + v_i x* I_i v_i.
    Inward: tau_i = S_i^T f_i, f_{i-1} += X_i^T f_i. Then tau_i += gear_ratio^2 J_m qdd_i
    (reflected rotor inertia) and, unless friction=False, viscous qd_i + coulomb sign(qd_i).

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd, qdd: joint positions, velocities, accelerations: (n,) each, or (N, n) each for
            N states.
        params: the free parameters' values (see `numeric_model`).
        gravity, friction: include gravity, resp. joint friction.

    Returns:
        Joint efforts tau, (n,) or (N, n).

    Raises:
        SymdynError: a vector of the wrong shape or not numeric, or bad parameter values.
    """
    mdl, (q, qd, qdd), single = checked_inputs("rnea", robot, params, ("q", q), ("qd", qd), ("qdd", qdd))
    return _out(_rnea(mdl, q, qd, qdd, gravity, friction), single)


def _mass_matrix(mdl: NumericModel, q: np.ndarray) -> np.ndarray:
    """M for a batch q (N, n) -> (N, n, n); see `mass_matrix`."""
    N, n = q.shape
    X = _motion_transforms(_joint_poses(mdl, q))
    S = _subspaces(mdl)
    Ic = [np.broadcast_to(mdl.spatial_inertia[i], (N, 6, 6)).copy() for i in range(n)]
    M = np.zeros((N, n, n))
    for i in reversed(range(n)):
        if i > 0:
            Ic[i - 1] += np.swapaxes(X[i], -1, -2) @ Ic[i] @ X[i]
        F = Ic[i] @ S[i]
        M[:, i, i] = F @ S[i] + mdl.reflected[i]
        for j in range(i, 0, -1):
            F = _mv(np.swapaxes(X[j], -1, -2), F)
            M[:, i, j - 1] = M[:, j - 1, i] = F @ S[j - 1]
    return M


def mass_matrix(robot, q, params=None) -> np.ndarray:
    """Joint-space inertia M(q) by the composite-rigid-body algorithm (body frames).

    Featherstone (2008), sec. 6.2. Composite inertias Ic_{i-1} += X_i^T Ic_i X_i (inward);
    F = Ic_i S_i, M_ii = S_i^T F, and for j < i, M_ij = M_ji = S_j^T (X_{j+1}^T ... X_i^T F).
    The diagonal also gets the reflected rotor inertia gear_ratio^2 J_m.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        M, (n, n) or (N, n, n).
    """
    mdl, (q,), single = checked_inputs("mass_matrix", robot, params, ("q", q))
    return _out(_mass_matrix(mdl, q), single)


def gravity_torque(robot, q, params=None) -> np.ndarray:
    """G(q) = rnea(q, 0, 0) without friction: the joint efforts that hold the arm still.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        G, (n,) or (N, n).
    """
    mdl, (q,), single = checked_inputs("gravity_torque", robot, params, ("q", q))
    z = np.zeros_like(q)
    return _out(_rnea(mdl, q, z, z, True, False), single)


def bias_torque(robot, q, qd, params=None) -> np.ndarray:
    """V(q, qd) = rnea(q, qd, 0) with gravity and friction off: Coriolis and centrifugal terms.

    (Not the "bias" V + G + F of `symdyn.Dynamics`.)

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd: (n,) each, or (N, n) each.
        params: the free parameters' values (see `numeric_model`).

    Returns:
        V, (n,) or (N, n).
    """
    mdl, (q, qd), single = checked_inputs("bias_torque", robot, params, ("q", q), ("qd", qd))
    return _out(_rnea(mdl, q, qd, np.zeros_like(q), False, False), single)


def friction_torque(robot, qd, params=None) -> np.ndarray:
    """F(qd)_i = viscous_i qd_i + coulomb_i sign(qd_i) (joint space; sign(0) = 0).

    Args:
        robot: a `symdyn.Robot` with n joints.
        qd: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        F, (n,) or (N, n).
    """
    mdl, (qd,), single = checked_inputs("friction_torque", robot, params, ("qd", qd))
    return _out(mdl.viscous * qd + mdl.coulomb * np.sign(qd), single)


def forward_dynamics(robot, q, qd, tau, params=None) -> np.ndarray:
    """qdd solving M(q) qdd = tau - V(q, qd) - G(q) - F(qd) (numpy.linalg.solve, joint space).

    V + G + F comes from one RNEA pass with qdd = 0, M from the CRBA.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd, tau: (n,) each, or (N, n) each.
        params: the free parameters' values (see `numeric_model`).

    Returns:
        qdd, (n,) or (N, n).
    """
    mdl, (q, qd, tau), single = checked_inputs(
        "forward_dynamics", robot, params, ("q", q), ("qd", qd), ("tau", tau)
    )
    h = _rnea(mdl, q, qd, np.zeros_like(q), True, True)
    M = _mass_matrix(mdl, q)
    return _out(np.linalg.solve(M, (tau - h)[..., None])[..., 0], single)


def kinetic_energy(robot, q, qd, params=None) -> float | np.ndarray:
    """T = sum_i 1/2 v_i^T I_i v_i + 1/2 gear_ratio_i^2 J_m,i qd_i^2 (= 1/2 qd^T M qd).

    v_i is the spatial velocity of body i and I_i its spatial inertia, both in body i's frame
    at its origin.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd: (n,) each, or (N, n) each.
        params: the free parameters' values (see `numeric_model`).

    Returns:
        T, a float or (N,).
    """
    mdl, (q, qd), single = checked_inputs("kinetic_energy", robot, params, ("q", q), ("qd", qd))
    X = _motion_transforms(_joint_poses(mdl, q))
    S = _subspaces(mdl)
    v = np.zeros((len(q), 6))
    T = 0.5 * (mdl.reflected * qd**2).sum(axis=1)
    for i in range(mdl.n):
        v = _mv(X[i], v) + S[i] * qd[:, i, None]
        T = T + 0.5 * np.einsum("ni,ij,nj->n", v, mdl.spatial_inertia[i], v)
    return float(T[0]) if single else T


def _poses(mdl: NumericModel, q: np.ndarray) -> list[np.ndarray]:
    """Base-frame poses base_T_i (N,4,4), composed from the joint transforms."""
    N = len(q)
    T = np.broadcast_to(np.eye(4), (N, 4, 4))
    out = []
    for E, r in _joint_poses(mdl, q):
        J = np.zeros((N, 4, 4))
        J[:, :3, :3], J[:, :3, 3], J[:, 3, 3] = E, r, 1.0
        T = T @ J
        out.append(T)
    return out


def forward_kinematics(robot, q, params=None) -> list[np.ndarray]:
    """The 4x4 pose base_T_i = prod_k parent_T_k(q_k) of every body frame, in the base frame.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        A list of n arrays (4, 4), or (N, 4, 4) for a batch.
    """
    mdl, (q,), single = checked_inputs("forward_kinematics", robot, params, ("q", q))
    return [_out(T, single) for T in _poses(mdl, q)]


def _com_positions(mdl: NumericModel, q: np.ndarray) -> np.ndarray:
    """Centres of mass in the base frame for a batch q (N, n) -> (N, n, 3)."""
    Ts = _poses(mdl, q)
    return np.stack([_mv(T[:, :3, :3], mdl.com[i]) + T[:, :3, 3] for i, T in enumerate(Ts)], 1)


def link_com_positions(robot, q, params=None) -> np.ndarray:
    """Centres of mass in the base frame, p_ci = base_R_i com_i + base_p_i.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        (n, 3), or (N, n, 3) for a batch.
    """
    mdl, (q,), single = checked_inputs("link_com_positions", robot, params, ("q", q))
    return _out(_com_positions(mdl, q), single)


def potential_energy(robot, q, params=None) -> float | np.ndarray:
    """U = -sum_i m_i g^T p_ci, gravity g and centres of mass p_ci in the base frame.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        U, a float or (N,).
    """
    mdl, (q,), single = checked_inputs("potential_energy", robot, params, ("q", q))
    U = -np.einsum("i,nij,j->n", mdl.mass, _com_positions(mdl, q), mdl.gravity)
    return float(U[0]) if single else U


class _CallableModule(types.ModuleType):
    """`symdyn.rnea` is both this module and the public function symdyn.rnea(robot, q, qd, qdd)."""

    def __call__(self, robot, q, qd, qdd, params=None, **kwargs):
        return rnea(robot, q, qd, qdd, params, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
