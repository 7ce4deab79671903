"""The independent numeric oracle: rigid-body dynamics of a `Robot` with NumPy only.

Every symbolic derivation and every generated function is judged against this
module, so it shares no code with them: it reads the `Robot` model, converts it
once to NumPy arrays (`numeric_model`, cached per robot and parameter values, in
symdyn.oracle.inputs with the checks of every argument) and never calls SymPy while
evaluating. It also uses a different formulation
from the lecture's link-frame recursion (slides 14-15): Featherstone's
spatial-vector algorithms in body coordinates, with motion vectors
v = [omega; v_O] and force vectors f = [n_O; f] (angular part first, both
taken at the body-frame origin O and expressed in body-frame axes):

* inverse dynamics: the recursive Newton-Euler algorithm (RNEA) on spatial
  vectors, gravity entered as a fictitious base acceleration a_0 = [0; -g];
* mass matrix: the composite-rigid-body algorithm (CRBA);
* energies and kinematics: poses composed in the base frame.

The links form a kinematic tree: body i moves relative to its parent lambda(i) (the base
for lambda(i) = -1; Featherstone's parent array, sec. 4.1.2) by
parent_T_i(q_i) = placement @ Rot(axis, q_i) (revolute, motion subspace S_i = [axis; 0])
or placement @ Trans(axis q_i) (prismatic, S_i = [0; axis]). Every public function takes
the n independent joint coordinates, as a single state (vectors of length n) or a batch
(arrays of shape (N, n)). A mimic joint follows another, q_j = multiplier q_i + offset:
the algorithms run on the nb bodies at q_b, qd_b = S qd, qdd_b = S qdd and the efforts come
back as S^T tau_b (M = S^T M_b S), by virtual work (Featherstone 2008, ch. 8: qd_b = S qd as a constraint).

On a floating robot (Robot.floating) rnea, mass_matrix, gravity_torque, bias_torque,
friction_torque, forward_dynamics and kinetic_energy take Pinocchio's vectors, q of NQ = 7 + n
entries and velocities, accelerations and efforts of NV = 6 + n (symdyn.oracle.floating).
"""

from __future__ import annotations

import numpy as np

from ..errors import SymdynError
from .floating import floating_inputs, floating_mass_matrix, floating_rnea, solve
from .inputs import (
    NumericModel,
    body_positions,
    body_rates,
    checked_inputs,
    numeric_model,
    project,
)
from .recursions import body_crba, body_rnea, joint_friction
from .singular import check_invertible
from .spatial import joint_poses, motion_transforms, mv, subspaces
from .tendons import tendon_efforts, tendon_kinetic, tendon_mass, tendon_potential

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


def _floating(robot) -> bool:
    """Whether the robot's base floats (symdyn.oracle.floating then evaluates its dynamics)."""
    return getattr(robot, "floating", False) is True


def _fixed_only(robot, where: str) -> None:
    """A SymdynError for a floating robot in a function that handles a fixed base only."""
    if _floating(robot):
        raise SymdynError(f"{where}: robot '{robot.name}' has a floating base: {where} is for a fixed base")


def _out(a: np.ndarray, single: bool) -> np.ndarray:
    return a[0] if single else a


def _rnea(mdl, q, qd, qdd, g_on: bool, f_on: bool) -> np.ndarray:
    """tau (N, n) for independent q, qd, qdd (N, n): the bodies' efforts, with rotor inertia and
    friction at the bodies' rates, projected by S^T; see `rnea`."""
    q_b, qd_b, qdd_b = body_positions(mdl, q), body_rates(mdl, qd), body_rates(mdl, qdd)
    base_a = np.zeros((len(q), 6))
    if g_on:
        base_a[:, 3:] = -mdl.gravity  # fictitious base acceleration a_0 = [0; -g]
    tau = body_rnea(mdl, q_b, qd_b, qdd_b, np.zeros((len(q), 6)), base_a)[0] + mdl.reflected * qdd_b
    if f_on:
        tau += joint_friction(mdl, qd_b)
    if len(mdl.tendon_coef):  # fixed tendons and joint springs (symdyn.oracle.tendons)
        tau += tendon_efforts(mdl, q_b, qd_b, qdd_b, g_on, f_on)
    return project(mdl, tau)


def rnea(robot, q, qd, qdd, params=None, *, gravity=True, friction=True) -> np.ndarray:
    """Inverse dynamics tau = M(q) qdd + V(q, qd) + G(q) + F(qd), by the spatial RNEA.

    Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 5.3; the lecture's 3-vector form
    is R. Grupen, "Dynamics" (2015), slides 14-15 (symdyn.algorithms.newton_euler).
    Body frames, spatial vectors at each body origin, p = lambda(i) the parent (v_p = 0 and
    a_p = [0; -g] for the base: gravity in the base frame; a_p = 0 with gravity=False).
    Outward: v_i = X_i v_p + S_i qd_i, a_i = X_i a_p + S_i qdd_i + v_i x S_i qd_i; body force
    f_i = I_i a_i + v_i x* I_i v_i. Inward: tau_i = S_i^T f_i, f_p += X_i^T f_i. Then
    tau_i += gear_ratio^2 J_m qdd_i (reflected rotor inertia) and, unless friction=False,
    viscous qd_i + coulomb sign(qd_i); all per body at q_b, qd_b, qdd_b, then tau = S^T tau_b.

    Args:
        robot: a `symdyn.Robot` with n independent joints.
        q, qd, qdd: joint positions, velocities, accelerations: (n,) each, or (N, n) each for
            N states.
        params: the free parameters' values (see `numeric_model`).
        gravity, friction: include gravity, resp. joint friction.

    Returns:
        Joint efforts tau, (n,) or (N, n).

    Raises:
        SymdynError: a vector of the wrong shape or not numeric, or bad parameter values.
    """
    if _floating(robot):
        mdl, (q, v, a), single = floating_inputs(
            "rnea", robot, params, ("q", q, "q"), ("v", qd, "v"), ("a", qdd, "v")
        )
        return _out(floating_rnea(mdl, q, v, a, gravity, friction), single)
    mdl, (q, qd, qdd), single = checked_inputs("rnea", robot, params, ("q", q), ("qd", qd), ("qdd", qdd))
    return _out(_rnea(mdl, q, qd, qdd, gravity, friction), single)


def _mass_matrix(mdl: NumericModel, q: np.ndarray) -> np.ndarray:
    """M for a batch of independent q (N, n) -> (N, n, n); see `mass_matrix`."""
    M = body_crba(mdl, body_positions(mdl, q))[0] + np.diag(mdl.reflected) + tendon_mass(mdl)
    return mdl.selection.T @ M @ mdl.selection


def mass_matrix(robot, q, params=None) -> np.ndarray:
    """Joint-space inertia M(q) by the composite-rigid-body algorithm (body frames).

    Featherstone (2008), sec. 6.2. Composite inertias Ic_lambda(i) += X_i^T Ic_i X_i (inward);
    F = Ic_i S_i, M_ii = S_i^T F, and for each ancestor j of i, M_ij = M_ji = S_j^T F with F
    carried down the path, F <- X_k^T F; the other entries are zero (joints on different
    branches). The diagonal also gets the reflected rotor inertia gear_ratio^2 J_m; with
    mimic joints this is M_b of the bodies and M = S^T M_b S.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        M, (n, n) or (N, n, n).
    """
    if _floating(robot):
        mdl, (q,), single = floating_inputs("mass_matrix", robot, params, ("q", q, "q"))
        return _out(floating_mass_matrix(mdl, q), single)
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
    if _floating(robot):
        mdl, (q,), single = floating_inputs("gravity_torque", robot, params, ("q", q, "q"))
        z = np.zeros((len(q), mdl.n + 6))
        return _out(floating_rnea(mdl, q, z, z, True, False), single)
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
    if _floating(robot):
        mdl, (q, v), single = floating_inputs("bias_torque", robot, params, ("q", q, "q"), ("v", qd, "v"))
        return _out(floating_rnea(mdl, q, v, np.zeros_like(v), False, False), single)
    mdl, (q, qd), single = checked_inputs("bias_torque", robot, params, ("q", q), ("qd", qd))
    return _out(_rnea(mdl, q, qd, np.zeros_like(q), False, False), single)


def friction_torque(robot, qd, params=None) -> np.ndarray:
    """F(qd)_i = viscous_i qd_i + coulomb_i sign(qd_i) (joint space; sign(0) = 0; with
    direction-dependent friction + coulomb_i for qd_i > 0, - coulomb_minus_i for qd_i < 0), per body at
    qd_b = S qd and projected, S^T F_b, for mimic joints.

    Args:
        robot: a `symdyn.Robot` with n joints.
        qd: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        F, (n,) or (N, n).
    """
    if _floating(robot):  # none on the free flyer
        mdl, (v,), single = floating_inputs("friction_torque", robot, params, ("v", qd, "v"))
        F = project(mdl, joint_friction(mdl, body_rates(mdl, v[:, 6:])))
        return _out(np.concatenate([np.zeros((len(v), 6)), F], 1), single)
    mdl, (qd,), single = checked_inputs("friction_torque", robot, params, ("qd", qd))
    qd_b = body_rates(mdl, qd)
    F = joint_friction(mdl, qd_b)
    if len(mdl.tendon_coef):
        F = F + tendon_efforts(mdl, np.zeros_like(qd_b), qd_b, np.zeros_like(qd_b), False, True)
    return _out(project(mdl, F), single)


def forward_dynamics(robot, q, qd, tau, params=None) -> np.ndarray:
    """qdd solving M(q) qdd = tau - V(q, qd) - G(q) - F(qd) (numpy.linalg.solve, joint space).

    V + G + F comes from one RNEA pass with qdd = 0, M from the CRBA.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q, qd, tau: (n,) each, or (N, n) each.
        params: the free parameters' values (see `numeric_model`).

    Returns:
        qdd, (n,) or (N, n).

    Raises:
        SymdynError: bad arguments (see `rnea`), or M(q) singular (symdyn.oracle.singular: a
            pivot of M = L D L^T vanishes), naming the joint and why: it moves no mass or
            inertia, or only mass on its own axis, or only as the joints before it do.
    """
    if _floating(robot):
        mdl, (q, v, tau), single = floating_inputs(
            "forward_dynamics", robot, params, ("q", q, "q"), ("v", qd, "v"), ("tau", tau, "v")
        )
        h = floating_rnea(mdl, q, v, np.zeros_like(v), True, True)
        return _out(solve(floating_mass_matrix(mdl, q), tau - h, "forward_dynamics"), single)
    mdl, (q, qd, tau), single = checked_inputs(
        "forward_dynamics", robot, params, ("q", q), ("qd", qd), ("tau", tau)
    )
    h = _rnea(mdl, q, qd, np.zeros_like(q), True, True)
    M = _mass_matrix(mdl, q)
    check_invertible(mdl, M, "forward_dynamics")
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
    if _floating(robot):
        mdl, (q, v), single = floating_inputs("kinetic_energy", robot, params, ("q", q, "q"), ("v", qd, "v"))
        T = 0.5 * np.einsum("ni,nij,nj->n", v, floating_mass_matrix(mdl, q), v)
        return float(T[0]) if single else T
    mdl, (q, qd), single = checked_inputs("kinetic_energy", robot, params, ("q", q), ("qd", qd))
    X = motion_transforms(joint_poses(mdl, body_positions(mdl, q)))
    S = subspaces(mdl)
    qd_b = body_rates(mdl, qd)
    T = 0.5 * (mdl.reflected * qd_b**2).sum(axis=1) + tendon_kinetic(mdl, qd_b)
    vs: list[np.ndarray] = []
    for i in range(mdl.nb):
        p = mdl.parent[i]
        v = (mv(X[i], vs[p]) if p >= 0 else 0.0) + S[i] * qd_b[:, i, None]
        vs.append(v)
        T = T + 0.5 * np.einsum("ni,ij,nj->n", v, mdl.spatial_inertia[i], v)
    return float(T[0]) if single else T


def _poses(mdl: NumericModel, q: np.ndarray) -> list[np.ndarray]:
    """Base-frame poses base_T_i (N,4,4) for independent q (N, n), composed along the tree."""
    N = len(q)
    base = np.broadcast_to(np.eye(4), (N, 4, 4))
    out: list[np.ndarray] = []
    for i, (E, r) in enumerate(joint_poses(mdl, body_positions(mdl, q))):
        J = np.zeros((N, 4, 4))
        J[:, :3, :3], J[:, :3, 3], J[:, 3, 3] = E, r, 1.0
        p = mdl.parent[i]
        out.append((out[p] if p >= 0 else base) @ J)
    return out


def forward_kinematics(robot, q, params=None) -> list[np.ndarray]:
    """The 4x4 pose base_T_i = base_T_lambda(i) parent_T_i(q_i) of every body frame, base frame.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        A list of nb arrays (4, 4), or (N, 4, 4) for a batch, one per link.
    """
    _fixed_only(robot, "forward_kinematics")
    mdl, (q,), single = checked_inputs("forward_kinematics", robot, params, ("q", q))
    return [_out(T, single) for T in _poses(mdl, q)]


def _com_positions(mdl: NumericModel, q: np.ndarray) -> np.ndarray:
    """Centres of mass in the base frame for a batch q (N, n) -> (N, nb, 3)."""
    Ts = _poses(mdl, q)
    return np.stack([mv(T[:, :3, :3], mdl.com[i]) + T[:, :3, 3] for i, T in enumerate(Ts)], 1)


def link_com_positions(robot, q, params=None) -> np.ndarray:
    """Centres of mass in the base frame, p_ci = base_R_i com_i + base_p_i.

    Args:
        robot: a `symdyn.Robot` with n joints.
        q: (n,) or (N, n).
        params: the free parameters' values (see `numeric_model`).

    Returns:
        (nb, 3), or (N, nb, 3) for a batch, one row per link.
    """
    _fixed_only(robot, "link_com_positions")
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
    _fixed_only(robot, "potential_energy")
    mdl, (q,), single = checked_inputs("potential_energy", robot, params, ("q", q))
    U = -np.einsum("i,nij,j->n", mdl.mass, _com_positions(mdl, q), mdl.gravity)
    U = U + tendon_potential(mdl, body_positions(mdl, q))
    return float(U[0]) if single else U
