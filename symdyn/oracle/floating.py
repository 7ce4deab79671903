"""The oracle on a floating base: inverse dynamics and the mass matrix of a robot whose base is
joined to the world by a free flyer (NumPy only; symdyn.model.free_flyer has the conventions).

Pinocchio's vectors: q = [x, y, z, qx, qy, qz, qw, joints] (NQ = 7 + n), v = [base linear
velocity, base angular velocity (both in the base frame), joint rates] (NV = 6 + n), a its time
derivative, tau = [force, moment on the base (base frame), joint torques]. Inside, the base is
body 0 of Featherstone's spatial algorithms (angular part first; Rigid Body Dynamics Algorithms,
2008, sec. 9.3): its twist v_0 and acceleration a_0 are given in the base frame, gravity enters as
the fictitious acceleration a_0 - [0; R^T g] (R = world_R_base of the normalised quaternion), the
base rows of tau are the wrench f_0 = I_0 a_0 + v_0 x* I_0 v_0 + sum X_i^T f_i of the whole
robot, and the base block of M is the composite inertia of the whole robot in the base frame.
"""

from __future__ import annotations

import numpy as np

from ..errors import SymdynError
from ..model.quaternion_norm import check_quaternions
from .inputs import NumericModel, body_positions, body_rates, checked_inputs, project
from .recursions import body_crba, body_rnea, joint_friction
from .spatial import crm, mv

__all__ = [
    "floating_inputs",
    "base_rotation",
    "floating_rnea",
    "floating_mass_matrix",
    "solve",
]

#: Featherstone's [angular; linear] <-> Pinocchio's [linear; angular] (the permutation is its own inverse)
_SWAP = np.array([3, 4, 5, 0, 1, 2])
_WHAT = {
    "q": "NQ = 7 + joints: base position, quaternion, joints",
    "v": "NV = 6 + joints: base twist, joints",
}


def floating_inputs(where: str, robot, params, *named: tuple[str, object, str]):
    """The numeric model and the vectors of a floating robot, checked: named (name, value, kind)
    with kind "q" (NQ entries) or "v" (NV entries, for v, a and tau); as in checked_inputs."""
    mdl, _, _ = checked_inputs(where, robot, params)
    sizes = {"q": mdl.n + 7, "v": mdl.n + 6}
    out = checked_inputs(where, robot, params, *((n, x, sizes[k], _WHAT[k]) for n, x, k in named))
    for (name, _, kind), array in zip(named, out[1], strict=True):
        if kind == "q":  # the norms whose square the generated code holds (symdyn.model.quaternion_norm)
            check_quaternions(array[0] if out[2] else array, f"{where}: {name}")
    return out


def base_rotation(quat: np.ndarray) -> np.ndarray:
    """world_R_base (N,3,3) of quaternions (N,4) = (qx, qy, qz, qw): the rotation of q / |q|,
    R = 1 + s (qw [u]x + [u]x^2) with u = (qx, qy, qz) and s = 2 / |q|^2 (not finite for q = 0)."""
    u, w = quat[:, :3], quat[:, 3]
    s = 2.0 / np.einsum("ni,ni->n", quat, quat)
    U = crm(np.concatenate([u, u], 1))[:, :3, :3]
    return np.eye(3) + s[:, None, None] * (w[:, None, None] * U + U @ U)


def floating_rnea(mdl: NumericModel, q: np.ndarray, v: np.ndarray, a: np.ndarray, g_on: bool, f_on: bool):
    """tau (N, NV) = [wrench on the base (force, moment; base frame), joint efforts] for q (N, NQ),
    v, a (N, NV): the spatial RNEA with the base as a moving body (module documentation); the
    joints' rotor inertia and friction as on a fixed base, none on the base."""
    N = len(q)
    v0, a0 = v[:, :6][:, _SWAP], a[:, :6][:, _SWAP].copy()
    if g_on:
        a0[:, 3:] -= mv(np.swapaxes(base_rotation(q[:, 3:7]), -1, -2), np.broadcast_to(mdl.gravity, (N, 3)))
    qj, vj, aj = q[:, 7:], v[:, 6:], a[:, 6:]
    q_b, qd_b, qdd_b = body_positions(mdl, qj), body_rates(mdl, vj), body_rates(mdl, aj)
    tau_b, f0 = body_rnea(mdl, q_b, qd_b, qdd_b, v0, a0)
    tau_b = tau_b + mdl.reflected * qdd_b
    if f_on:
        tau_b = tau_b + joint_friction(mdl, qd_b)
    I0 = mdl.base_inertia
    f0 = f0 + mv(I0, a0) - mv(np.swapaxes(crm(v0), -1, -2), mv(I0, v0))
    return np.concatenate([f0[:, _SWAP], project(mdl, tau_b)], 1)


def floating_mass_matrix(mdl: NumericModel, q: np.ndarray) -> np.ndarray:
    """M (N, NV, NV) for q (N, NQ) by the CRBA: [[Ic_0, F^T], [F, M_joints]] with Ic_0 the composite
    inertia of the whole robot (base body included) in the base frame and F the joints' columns
    carried down to the base (Pinocchio's order: linear rows before angular ones). M does not
    depend on the base's position or orientation."""
    M_b, F0, Ic0 = body_crba(mdl, body_positions(mdl, q[:, 7:]))
    S = mdl.selection
    n = mdl.n
    M = np.zeros((len(q), n + 6, n + 6))
    M[:, :6, :6] = (Ic0 + mdl.base_inertia)[:, _SWAP][:, :, _SWAP]
    M[:, :6, 6:] = F0[:, _SWAP] @ S
    M[:, 6:, :6] = np.swapaxes(M[:, :6, 6:], -1, -2)
    M[:, 6:, 6:] = S.T @ (M_b + np.diag(mdl.reflected)) @ S
    return M


def solve(M: np.ndarray, rhs: np.ndarray, where: str) -> np.ndarray:
    """x with M x = rhs for a batch (N, NV, NV), (N, NV); a singular M is a SymdynError."""
    try:
        return np.linalg.solve(M, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        raise SymdynError(f"{where}: the mass matrix of the floating robot is singular") from None
