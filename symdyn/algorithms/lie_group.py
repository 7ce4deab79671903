"""Configuration arithmetic of a floating robot, symbolic: q (+) v dt and difference(q0, q1).

The configuration q = [p, quat, q_joints] (symdyn.model.free_flyer: p the base origin in the
world, quat = (qx, qy, qz, qw) the unit quaternion of world_R_base) lives on SE(3) x R^n and
the velocity v = [nu, omega, qd] (the base twist in the base frame) in its tangent space. As in
Pinocchio's JointModelFreeFlyer (SpecialEuclideanOperationTpl<3>), the base part is the SE(3)
exponential and logarithm in the local frame, not R^3 x SO(3) separately; the joints add.

integrate (q_next = q (+) v dt), with (nu, omega) = (v_base, w_base) dt, theta = |omega|:

    M_next = M_0 exp6(nu, omega),    exp6 = (exp3(omega), V(omega) nu),
    V      = I + b [omega]x + c [omega]x^2,   b = (1 - cos theta)/theta^2,
                                              c = (theta - sin theta)/theta^3,
    p_next = p_0 + R_0 V nu,
    quat_next = normalise(s quat_0 (x) (a omega, cos(theta/2))),   a = sin(theta/2)/theta,

with s = -1 when cos(theta/2) < 0 and +1 otherwise, so that quat_next . quat_0 >= 0 as
Pinocchio keeps it (the quaternion of a rotation by more than pi is the one on quat_0's side);
q_joints_next = q_joints + qd dt.

difference (v = difference(q0, q1), the v with q0 (+) v = q1; Pinocchio's difference):

    dq = s conj(quat_0) (x) quat_1 = (u, w),   s = -1 when that product's scalar is < 0,
    theta = 2 atan2(|u|, w) in [0, pi],   omega = (theta / |u|) u     (log3 of R_0^T R_1),
    p = R_0^T (p_1 - p_0),
    nu = alpha p - 1/2 omega x p + beta (omega . p) omega     (log6, V(omega)^-1 p),
    alpha = (theta/2) sin(theta) / (1 - cos theta),   beta = (1 - alpha) / theta^2,

and the joints subtract. Every coefficient that is 0/0 at theta = 0 (or |u| = 0) is a guarded
series (`guarded`): its Taylor polynomial below a threshold and the exact form above it, chosen
by a 0/1 step (Heaviside(x, 0), printed as a comparison in every target) with the exact form
evaluated at a shifted, non-zero argument when unused, so that the generated code has no
branch and never divides by zero, at v = 0 and at q0 = q1 included.

The quaternions of q, q0 and q1 must be of unit norm (the rotations are the polynomial
quaternion_rotation, exact only for unit quaternions); integrate returns a unit quaternion.

References: Pinocchio (lie-group/special-euclidean.hpp, spatial/explog.hpp); Sola, Deray and
Atchuthan, A micro Lie theory for state estimation in robotics (2018), eq. (156), (172).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.free_flyer import NQ_BASE, NV_BASE, quaternion_rotation
from ..symbolic.program import Program

__all__ = ["guarded", "integrate", "difference", "SERIES_BELOW"]

#: theta^2 below which the series replaces a 0/0 coefficient (the series are exact to 1e-16
#: there; above it the exact forms lose at most about 1e-13 to cancellation).
SERIES_BELOW = sp.Rational(1, 100)
_X = sp.Symbol("x", nonnegative=True)


def guarded(
    exact: sp.Expr, x2: sp.Expr, prog: Program, hint: str, below=SERIES_BELOW, order: int = 12
) -> sp.Expr:
    """A coefficient f(x) that is even in x and 0/0 at x = 0, given by `exact` in the symbol x
    (symdyn.algorithms.lie_group._X), as a branch-free function of x2 = x^2 (module docstring):

        step = H(x2 - below),  f = step f(sqrt(x2 + 1 - step)) + (1 - step) T(x2),

    T the Taylor polynomial of f about 0 to x^order (terms up to x^(order - 2))."""
    series = sp.series(exact, _X, 0, order).removeO()
    poly = sp.expand(series).subs(_X, sp.sqrt(x2))
    step = prog.let(sp.Heaviside(x2 - below, 0), f"{hint}s")
    x = prog.let(sp.sqrt(x2 + 1 - step), f"{hint}x")
    return prog.let(step * exact.subs(_X, x) + (1 - step) * sp.expand(poly), hint)


def _cross(a: Sequence, b: Sequence) -> list:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a: Sequence, b: Sequence):
    return sum((x * y for x, y in zip(a, b, strict=True)), sp.S.Zero)


def _quat_mul(a: Sequence, b: Sequence) -> list:
    """Hamilton product a (x) b of quaternions (x, y, z, w), scalar last."""
    av, aw, bv, bw = a[:3], a[3], b[:3], b[3]
    c = _cross(av, bv)
    return [aw * bv[i] + bw * av[i] + c[i] for i in range(3)] + [aw * bw - _dot(av, bv)]


def _check(q: Sequence, n: int, what: str, size: int) -> None:
    assert len(q) == size + n, f"{what}: {len(q)} entries, not {size} + {n}"


def integrate(n: int, q: Sequence, v: Sequence, dt, prog: Program) -> list[sp.Expr]:
    """q (+) v dt of a floating robot with n joints (module docstring): NQ = 7 + n entries."""
    _check(q, n, "q", NQ_BASE)
    _check(v, n, "v", NV_BASE)
    p0, quat0 = list(q[:3]), list(q[3:7])
    nu = [prog.let(v[i] * dt, "inu") for i in range(3)]
    om = [prog.let(v[3 + i] * dt, "iom") for i in range(3)]
    th2 = prog.let(_dot(om, om), "ith")
    a = guarded(sp.sin(_X / 2) / _X, th2, prog, "ia")
    b = guarded((1 - sp.cos(_X)) / _X**2, th2, prog, "ib")
    c = guarded((_X - sp.sin(_X)) / _X**3, th2, prog, "ic")
    half = prog.let(sp.cos(sp.sqrt(th2) / 2), "ich")
    # V nu = nu + b omega x nu + c omega x (omega x nu)
    wxn = [prog.let(e, "iwn") for e in _cross(om, nu)]
    wwxn = _cross(om, wxn)
    Vnu = [prog.let(nu[i] + b * wxn[i] + c * wwxn[i], "iVn") for i in range(3)]
    R0 = quaternion_rotation(*quat0)
    p_next = [p0[i] + sum((R0[i, j] * Vnu[j] for j in range(3)), sp.S.Zero) for i in range(3)]
    sign = prog.let(1 - 2 * sp.Heaviside(-half, 0), "isg")
    dquat = [sign * a * om[i] for i in range(3)] + [sign * half]
    raw = [prog.let(e, "iqr") for e in _quat_mul(quat0, dquat)]
    inv_norm = prog.let(1 / sp.sqrt(_dot(raw, raw)), "iqn")
    quat_next = [r * inv_norm for r in raw]
    joints = [q[NQ_BASE + j] + v[NV_BASE + j] * dt for j in range(n)]
    return p_next + quat_next + joints


def difference(n: int, q0: Sequence, q1: Sequence, prog: Program) -> list[sp.Expr]:
    """difference(q0, q1) of a floating robot with n joints (module docstring): NV = 6 + n entries."""
    _check(q0, n, "q0", NQ_BASE)
    _check(q1, n, "q1", NQ_BASE)
    quat0, quat1 = list(q0[3:7]), list(q1[3:7])
    conj0 = [-quat0[0], -quat0[1], -quat0[2], quat0[3]]
    raw = [prog.let(e, "dqr") for e in _quat_mul(conj0, quat1)]
    sign = prog.let(1 - 2 * sp.Heaviside(-raw[3], 0), "dsg")
    u = [prog.let(sign * e, "du") for e in raw[:3]]
    w = prog.let(sign * raw[3], "dw")
    u2 = prog.let(_dot(u, u), "dun")
    # omega = (2 atan2(|u|, w) / |u|) u; below the threshold 2 atan(x / w) / x = 2/w (1 - x^2/(3 w^2) + ...)
    step = prog.let(sp.Heaviside(u2 - sp.Rational(1, 10**12), 0), "dus")
    un = prog.let(sp.sqrt(u2 + 1 - step), "dux")
    series = 2 / w - sp.Rational(2, 3) * u2 / w**3
    ratio = prog.let(step * 2 * sp.atan2(un, w) / un + (1 - step) * series, "dr")
    om = [prog.let(ratio * e, "dom") for e in u]
    th2 = prog.let(_dot(om, om), "dth")
    alpha = guarded(_X / 2 * sp.sin(_X) / (1 - sp.cos(_X)), th2, prog, "dal")
    beta = guarded((1 - _X / 2 * sp.sin(_X) / (1 - sp.cos(_X))) / _X**2, th2, prog, "dbe")
    R0 = quaternion_rotation(*quat0)
    dp = [q1[i] - q0[i] for i in range(3)]
    p = [prog.let(sum((R0[j, i] * dp[j] for j in range(3)), sp.S.Zero), "dp") for i in range(3)]
    wxp = _cross(om, p)
    wp = prog.let(_dot(om, p), "dwp")
    nu = [alpha * p[i] - wxp[i] / 2 + beta * wp * om[i] for i in range(3)]
    joints = [q1[NQ_BASE + j] - q0[NQ_BASE + j] for j in range(n)]
    return nu + om + joints
