"""The numeric oracle's configuration arithmetic and the derivatives of its inverse dynamics,
NumPy only: q (+) dq on a floating robot's Lie group, and dtau/dq (in the tangent space),
dtau/dv and M, as Pinocchio's computeRNEADerivatives defines them.

Independent of the symbolic code (symdyn.algorithms.lie_group, symdyn.algorithms.derivatives):
it reads only the model and differentiates the oracle's own inverse dynamics (symdyn.oracle.rnea).

Configuration arithmetic (Pinocchio's conventions, symdyn.model.free_flyer): on a floating base
q (+) dq moves the base by the SE(3) exponential of the base twist dq[:6] = (u, w) taken in the
base frame, on the right:

    world_T_base' = world_T_base Exp(u, w),   Exp(u, w) = (Exp(w), V(w) u),
    V(w) = 1 + (1 - cos t) / t^2 [w]x + (t - sin t) / t^3 [w]x^2,   t = |w|

(the quaternion times +-(sin(t/2) w / t, cos(t/2)), the sign that makes the scalar part
non-negative, as Pinocchio's integrate, then normalised) and adds dq[6:] to the joints; on a
fixed base q (+) dq = q + dq.

The derivatives, at one state (q, v, a), of the rigid-body inverse dynamics
tau = symdyn.rnea(robot, q, v, a, friction=False) (friction left out, as Pinocchio's RNEA does:
Coulomb friction has no derivative at v = 0):

* dtau/dq, column j = d/de tau(q (+) e e_j) at e = 0 (e_j the j-th tangent direction), by the
  five-point central difference
      (8 (tau(h) - tau(-h)) - (tau(2h) - tau(-2h))) / (12 h),   h = 1e-3,
  whose truncation error is h^4 / 30 |tau^(5)| (about 3e-14 of the scale of tau's derivatives in
  radians and metres) and rounding error 1.5 eps |tau| / h (about 3e-13 |tau|): together some
  1e-12 of the largest entry, the step being the one that balances them (h^5 = 45 eps / 4);
* dtau/dv, column j = (tau(v + e_j) - tau(v - e_j)) / 2: tau is quadratic in v, so this central
  difference has no truncation error at all (rounding only, eps |tau|);
* M = dtau/da: the oracle's mass matrix (the CRBA).

Every tau is evaluated in one batch of 6 NV states (symdyn.rnea takes (N, NQ) arrays).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..errors import SymdynError
from ..model.quaternion_norm import check_quaternions
from .floating import base_rotation
from .inputs import skew
from .rnea import mass_matrix, rnea

__all__ = ["RneaDerivatives", "integrate", "rnea_derivatives", "STEP"]

#: the five-point difference's step in the configuration (module docstring)
STEP = 1e-3


class RneaDerivatives(NamedTuple):
    """dtau/dq (NV x NV, tangent space), dtau/dv (NV x NV) and M (NV x NV)."""

    dtau_dq: np.ndarray
    dtau_dv: np.ndarray
    M: np.ndarray


def _array(robot, value, size: int, name: str, where: str) -> np.ndarray:
    """value as an (N, size) array of finite numbers (a single vector becomes N = 1)."""
    try:
        x = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SymdynError(f"{where}: robot '{robot.name}': {name} is not a vector of numbers") from None
    if x.ndim not in (1, 2) or x.shape[-1] != size or not np.all(np.isfinite(x)):
        raise SymdynError(
            f"{where}: robot '{robot.name}': {name} must be {size} finite numbers (or N rows of them), "
            f"got shape {x.shape}"
        )
    return x.reshape(-1, size)


def _exp_coefficients(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """sin(t/2) / t, (1 - cos t) / t^2 and (t - sin t) / t^3, finite at t = 0 (Taylor below 1e-2,
    where the formula would lose digits: the first omitted term is below 3e-18)."""
    half = 0.5 * np.sinc(t / (2 * np.pi))  # sin(t/2) / t
    small = t < 1e-2
    ts = np.where(small, 1.0, t)
    third = np.where(small, 1 / 6 - t**2 / 120 + t**4 / 5040, (ts - np.sin(ts)) / ts**3)
    return half, 2 * half**2, third


def integrate(robot, q, dq) -> np.ndarray:
    """q (+) dq (module docstring): q (NQ,) or (N, NQ), dq (NV,) or (N, NV) with the same N.

    Raises:
        SymdynError: vectors of the wrong size, not finite, or a zero base quaternion.
    """
    single = np.ndim(q) == 1 and np.ndim(dq) == 1
    Q = _array(robot, q, robot.nq, "q", "integrate")
    D = _array(robot, dq, robot.nv, "dq", "integrate")
    if len(Q) != len(D):
        raise SymdynError(f"integrate: robot '{robot.name}': q has {len(Q)} rows and dq {len(D)}")
    if not robot.floating:
        out = Q + D
        return out[0] if single else out
    quat = Q[:, 3:7]
    norm = np.linalg.norm(quat, axis=1)
    if np.any(norm == 0):
        raise SymdynError(f"integrate: robot '{robot.name}': the base quaternion q[3:7] is zero")
    check_quaternions(Q, f"integrate: robot '{robot.name}': q")
    quat = quat / norm[:, None]
    u, w = D[:, :3], D[:, 3:6]
    t = np.linalg.norm(w, axis=1)
    half, second, third = _exp_coefficients(t)
    W = skew(w)
    V = np.eye(3) + second[:, None, None] * W + third[:, None, None] * (W @ W)
    position = Q[:, :3] + np.einsum("nij,nj->ni", base_rotation(quat) @ V, u)
    # quat (x) (sin(t/2) w / t, cos(t/2)), scalar last: (a_w b_v + b_w a_v + a_v x b_v, a_w b_w - a_v . b_v)
    # (the sign that makes cos(t/2) >= 0: the same rotation, and Pinocchio's quaternion for |w| > pi)
    sign = np.where(np.cos(0.5 * t) < 0, -1.0, 1.0)
    bv, bw = (sign * half)[:, None] * w, sign * np.cos(0.5 * t)
    av, aw = quat[:, :3], quat[:, 3]
    new_v = aw[:, None] * bv + bw[:, None] * av + np.cross(av, bv)
    new_w = aw * bw - np.einsum("ni,ni->n", av, bv)
    rotated = np.concatenate([new_v, new_w[:, None]], 1)
    rotated /= np.linalg.norm(rotated, axis=1)[:, None]
    out = np.concatenate([position, rotated, Q[:, 7:] + D[:, 6:]], 1)
    return out[0] if single else out


def rnea_derivatives(robot, q, v, a, params=None, *, gravity: bool = True) -> RneaDerivatives:
    """dtau/dq (tangent space), dtau/dv and M of tau = rnea(q, v, a) without friction, at one
    state: q (NQ,), v and a (NV,) (module docstring for the differences and their errors).

    Raises:
        SymdynError: vectors of the wrong size or not finite, a zero base quaternion, bad
            parameter values.
    """
    q = _array(robot, q, robot.nq, "q", "rnea_derivatives")
    v = _array(robot, v, robot.nv, "v", "rnea_derivatives")
    a = _array(robot, a, robot.nv, "a", "rnea_derivatives")
    if len(q) != 1 or len(v) != 1 or len(a) != 1:
        raise SymdynError(f"rnea_derivatives: robot '{robot.name}': give one state (q, v, a), not a batch")
    if robot.floating and not np.any(q[0, 3:7]):
        raise SymdynError(f"rnea_derivatives: robot '{robot.name}': the base quaternion q[3:7] is zero")
    if robot.floating:
        check_quaternions(q[0], f"rnea_derivatives: robot '{robot.name}': q")
    nv = robot.nv
    E = np.eye(nv)
    steps = np.concatenate([E * STEP, -E * STEP, E * 2 * STEP, -E * 2 * STEP])
    Q = np.concatenate([integrate(robot, np.repeat(q, 4 * nv, 0), steps), np.repeat(q, 2 * nv, 0)])
    V = np.concatenate([np.repeat(v, 4 * nv, 0), v + E, v - E])
    tau = rnea(robot, Q, V, np.repeat(a, 6 * nv, 0), params, gravity=gravity, friction=False)
    p1, m1, p2, m2, pv, mv = np.split(tau, 6)
    dq = (8 * (p1 - m1) - (p2 - m2)) / (12 * STEP)
    return RneaDerivatives(dq.T, ((pv - mv) / 2).T, mass_matrix(robot, q[0], params))
