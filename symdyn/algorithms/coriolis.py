"""The Christoffel-symbol Coriolis matrix from composite bodies, in body frames, O(n^2).

Spatial vectors are pairs (angular, linear): a motion v = (w, u) with u the
velocity of the body-frame origin, a force f = (n, f) with n the moment about
the origin. s_k is joint k's motion subspace ((a_k, 0) revolute, (0, a_k)
prismatic), v_k the body velocity and psi_k = v_k x s_k the rate of change of
s_k as seen from the world. For the subtree rooted at m (the link and
everything outboard), I^c_m is its spatial inertia, h^c_m = sum I_i v_i its
momentum and Idot^c_m = sum (v_i x* I_i - I_i v_i x) the world rate of change
of I^c_m. Differentiating V_j = s_j^T dh^c_j/dt by qd_k (with
d a_i/d qd_k = 2 psi_k + s_k x v_i for the velocity-product accelerations)
gives, with m = max(j, k) and every vector carried into one frame,

    2 C_jk = s_j^T (s_k x* h^c_m + 2 I^c_m psi_k + Idot^c_m s_k)

which is the Christoffel form C = 1/2 dV/dqd (Echeandia and Wensing 2021 reach
the same result through their matrices B_i). With the half-quantities
H = h^c / 2 and P = Idot^c / 2 this reads, for j >= k,

    C_kj = s_k^T Y_j,               Y_j = P_j s_j + s_j x* H_j + I^c_j psi_j
    C_jk = s_k^T A_j + psi_k^T F_j,  A_j = P_j s_j - s_j x* H_j,  F_j = I^c_j s_j

(the lower triangle uses the symmetry of I^c and Idot^c and
<a, b x* f> = -<b, a x* f>). Only the three forces Y_j, A_j and F_j travel
inward, n <- R n + p x R f, f <- R f; nothing with an inertia is formed per
pair of joints, against one Newton-Euler tangent pass per column when C is
computed as 1/2 dV/dqd.

A zero-mass spatial inertia (h, I) carries P: for a body with first moment h
and rotational inertia I about its origin moving with (w, u),
Idot = (dh, dI) with dh = w x h + m u and dI = [w x] I - I [w x] - ([u x][h x] + [h x][u x]).
"""

from __future__ import annotations

import sympy as sp

from ..model.robot import Robot
from ..spatial import vectors as v3
from ..symbolic.program import Program
from .crba import Composite, Composites, Spatial, apply_inertia, motion_subspace, project, shift_inertia, sym3
from .frames import JointFrame
from .newton_euler import origin_inertia

__all__ = ["coriolis_matrix_composite"]

_HALF = sp.Rational(1, 2)
_ZERO3: v3.Vec = (sp.S.Zero,) * 3  # type: ignore[assignment]


def _let_spatial(program: Program, v: Spatial, hint: str) -> Spatial:
    """Name the six components of a spatial vector."""
    return program.let_vector(v[0], hint), program.let_vector(v[1], hint)


def _cross_motion(v: Spatial, s: Spatial) -> Spatial:
    """v x s for motion vectors: (w x ws, w x us + u x ws)."""
    (w, u), (ws, us) = v, s
    return v3.cross(w, ws), v3.add(v3.cross(w, us), v3.cross(u, ws))


def _cross_force(s: Spatial, f: Spatial) -> Spatial:
    """s x* f for a motion s and a force f: (ws x n + us x f, ws x f)."""
    (ws, us), (n, fl) = s, f
    return v3.add(v3.cross(ws, n), v3.cross(us, fl)), v3.cross(ws, fl)


def _inertia_rate(m: sp.Expr, h: v3.Vec, I: v3.Mat, v: Spatial, program: Program, k: str) -> Composite:
    """The world rate of change v x* I - I v x of a body's spatial inertia (m, h, I) moving
    with v = (w, u), as a zero-mass inertia (dh, dI)."""
    w, u = v
    dh = program.let_vector(v3.add(v3.cross(w, h), v3.scale(m, u)), f"Pd{k}_")
    columns = [v3.cross(w, (I[0][c], I[1][c], I[2][c])) for c in range(3)]  # [w x] I by columns
    K = [[columns[c][r] for c in range(3)] for r in range(3)]
    uh2 = v3._prod(2, v3.dot(u, h))
    dI = [
        [
            v3._sum((K[r][c], K[c][r], -v3._prod(u[r], h[c]), -v3._prod(h[r], u[c]), uh2 if r == c else 0))
            for c in range(3)
        ]
        for r in range(3)
    ]
    return sp.S.Zero, dh, sym3(program, dI, f"PI{k}_")


def coriolis_matrix_composite(
    robot: Robot, frames: list[JointFrame], composites: Composites, qd, program: Program
) -> sp.Matrix:
    """C(q, qd) with V = C qd and dM/dt - 2C skew-symmetric (Christoffel symbols), over the
    program's intermediates (`composites` from crba.composite_inertias); see the module
    docstring for the recursion."""
    n = robot.n
    mass, hc, Ic = composites
    s = [motion_subspace(link) for link in robot.links]
    # outward: body velocities and psi_k = v_k x s_k
    vel: list[Spatial] = []
    w, u = _ZERO3, _ZERO3
    for i in range(n):
        R, p = frames[i].R, frames[i].p
        u = v3.mul_t(R, v3.add(u, v3.cross(w, p)))
        w = v3.mul_t(R, w)
        w = program.let_vector(v3.add(w, v3.scale(qd[i], s[i][0])), f"w{i + 1}_")
        u = program.let_vector(v3.add(u, v3.scale(qd[i], s[i][1])), f"u{i + 1}_")
        vel.append((w, u))
    psi = [_let_spatial(program, _cross_motion(vel[k], s[k]), f"psi{k + 1}_") for k in range(n)]
    # inward: half momentum H and half inertia rate P of every subtree
    H: list[Spatial] = [((), ())] * n  # type: ignore[list-item]
    P: list[Composite] = [(sp.S.Zero, _ZERO3, ((sp.S.Zero,) * 3,) * 3)] * n  # type: ignore[list-item]
    for i in reversed(range(n)):
        link = robot.links[i]
        k = str(i + 1)
        m = sp.sympify(link.mass)
        h = v3.vec(v3.scale(m, v3.vec(link.com)))
        m2, h2, I2 = _HALF * m, v3.scale(_HALF, h), _halved(origin_inertia(link))
        half = apply_inertia(m2, h2, I2, vel[i])
        own = _inertia_rate(m2, h2, I2, vel[i], program, k)
        if i + 1 < n:
            child = frames[i + 1].force_to_parent(*H[i + 1], program, f"RH{k}_")
            half = (v3.add(half[0], child[0]), v3.add(half[1], child[1]))
            own = shift_inertia(frames[i + 1], P[i + 1], own, program, f"P{k}_")
        H[i] = _let_spatial(program, half, f"H{k}_")
        P[i] = own
    C = sp.zeros(n, n)
    for j in reversed(range(n)):
        k = str(j + 1)
        Ps = apply_inertia(sp.S.Zero, P[j][1], P[j][2], s[j])
        sH = _cross_force(s[j], H[j])
        Ipsi = apply_inertia(mass[j], hc[j], Ic[j], psi[j])
        Y = _let_spatial(program, (v3.add(Ps[0], sH[0], Ipsi[0]), v3.add(Ps[1], sH[1], Ipsi[1])), f"Y{k}_")
        A = _let_spatial(program, (v3.sub(Ps[0], sH[0]), v3.sub(Ps[1], sH[1])), f"A{k}_")
        F = _let_spatial(program, apply_inertia(mass[j], hc[j], Ic[j], s[j]), f"F{k}_")
        C[j, j] = program.let(project(s[j], Y), "C")
        for i in reversed(range(j)):
            frame = frames[i + 1]
            Y, A, F = (
                _let_spatial(program, frame.force_to_parent(*vec, program, f"R{tag}{k}_"), f"{tag}{k}_")
                for tag, vec in (("Y", Y), ("A", A), ("F", F))
            )
            C[i, j] = program.let(project(s[i], Y), "C")
            C[j, i] = program.let(v3._sum((project(s[i], A), project(psi[i], F))), "C")
    return C


def _halved(I: v3.Mat) -> v3.Mat:
    return tuple(tuple(v3._prod(_HALF, x) for x in row) for row in I)  # type: ignore[return-value]
