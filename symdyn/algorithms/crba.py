"""The mass matrix by the composite-rigid-body algorithm, symbolically, in body frames.

Each body i carries, about its body-frame origin, its mass m_i, first moment
h_i = m_i c_i and rotational inertia I_i = I_ci + m_i (c_i^T c_i 1 - c_i c_i^T).
The composite body of the subtree rooted at i adds its children, moved into
frame i (R, p: child frame in parent frame, h' = R h):

    m += m_j,   h += R h_j + m_j p,
    I += R I_j R^T - [h' x][p x] - [p x][h' x] - m_j [p x]^2

A unit acceleration of joint j makes the composite j exert the spatial force
(moment n about the origin, force f) = (I^c a, a x h^c) for a revolute joint
with axis a, or (h^c x a, m^c a) for a prismatic one. Carried inward,
n <- R n + p x R f, f <- R f, and projected on each joint i <= j, it gives
M_ij = a_i . n (revolute) or a_i . f (prismatic). O(n^2), against n
Newton-Euler passes.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.robot import Link, Robot
from ..spatial import vectors as v3
from ..symbolic.program import Program
from .frames import JointFrame
from .newton_euler import origin_inertia

__all__ = [
    "Composite",
    "Spatial",
    "motion_subspace",
    "apply_inertia",
    "Composites",
    "composite_inertias",
    "project",
    "shift_inertia",
    "sym3",
    "mass_matrix_crba",
    "gravity_composite",
]


Composite = tuple[sp.Expr, v3.Vec, v3.Mat]  # mass, first moment, rotational inertia about the origin


Spatial = tuple[v3.Vec, v3.Vec]  # (angular, linear): a motion (w, u) or a force (n, f)
_ZERO3: v3.Vec = (sp.S.Zero,) * 3  # type: ignore[assignment]


def motion_subspace(link: Link) -> Spatial:
    """The joint's motion for a unit rate: (a, 0) revolute, (0, a) prismatic (body frame)."""
    a = v3.vec(link.axis)
    return (a, _ZERO3) if link.joint == "revolute" else (_ZERO3, a)


def apply_inertia(m: sp.Expr, h: v3.Vec, I: v3.Mat, v: Spatial) -> Spatial:
    """The spatial inertia (m, h, I) times a motion (w, u): (I w + h x u, m u - h x w)."""
    w, u = v
    return v3.add(v3.mul(I, w), v3.cross(h, u)), v3.sub(v3.scale(m, u), v3.cross(h, w))


def project(m: Spatial, f: Spatial) -> sp.Expr:
    """m^T f for a motion m and a force f (a joint's share of a force, for m = s)."""
    return v3._sum((v3.dot(m[0], f[0]), v3.dot(m[1], f[1])))


def sym3(program: Program, I: Sequence[Sequence[sp.Expr]], hint: str) -> v3.Mat:
    """Name the 6 distinct entries of a symmetric 3x3 matrix."""
    e = {(r, c): program.let(I[r][c], hint) for r in range(3) for c in range(r, 3)}
    return tuple(tuple(e[(min(r, c), max(r, c))] for c in range(3)) for r in range(3))  # type: ignore[return-value]


def _skew_sq(p: v3.Vec) -> list[list[sp.Expr]]:
    """[p x]^2 = p p^T - (p^T p) 1."""
    pp = v3.dot(p, p)
    return [[v3._prod(p[r], p[c]) - (pp if r == c else 0) for c in range(3)] for r in range(3)]


def _sym_cross_term(u: v3.Vec, p: v3.Vec) -> list[list[sp.Expr]]:
    """[u x][p x] + [p x][u x] = u p^T + p u^T - 2 (u . p) 1."""
    up = v3.dot(u, p)
    return [
        [v3._sum((v3._prod(u[r], p[c]), v3._prod(p[r], u[c]), -2 * up if r == c else 0)) for c in range(3)]
        for r in range(3)
    ]


def shift_inertia(
    frame: JointFrame, child: Composite, own: Composite, program: Program, hint: str
) -> Composite:
    """own + child, the child's spatial inertia (about its origin, its axes) moved into the parent
    frame (R, p: child frame in parent frame, h' = R h):

        m = m_o + m_j,   h = h_o + R h_j + m_j p,
        I = I_o + R I_j R^T - [h' x][p x] - [p x][h' x] - m_j [p x]^2
    """
    R, p = frame.R, frame.p
    mj, hj, Ij = child
    mo, ho, Io = own
    Rh = program.let_vector(v3.mul(R, hj), f"{hint}Rh")
    m = program.let(v3._sum((mo, mj)), f"{hint}m")
    h = program.let_vector(v3.add(ho, Rh, v3.scale(mj, p)), f"{hint}h")
    RIR = frame.rotate_symmetric(Ij, program, f"{hint}r")
    cross = _sym_cross_term(Rh, p)  # type: ignore[arg-type]
    pp = _skew_sq(p)
    I = sym3(
        program,
        [
            [v3._sum((Io[r][k], RIR[r][k], -cross[r][k], -v3._prod(mj, pp[r][k]))) for k in range(3)]
            for r in range(3)
        ],
        f"{hint}I",
    )
    return m, h, I  # type: ignore[return-value]


Composites = tuple[list[sp.Expr], list[v3.Vec], list[v3.Mat]]  # per link: mass, h, I of its subtree


def composite_inertias(robot: Robot, frames: list[JointFrame], program: Program) -> Composites:
    """Mass, first moment and rotational inertia (about the body origin, body axes) of the
    subtree rooted at each link (the link and everything outboard of it)."""
    n = robot.n
    comp: list[Composite] = [(sp.S.Zero, (), ())] * n  # type: ignore[list-item]
    for j in reversed(range(n)):
        link = robot.links[j]
        m = sp.sympify(link.mass)
        own: Composite = (
            m,
            program.let_vector(v3.scale(m, v3.vec(link.com)), "h"),
            sym3(program, origin_inertia(link), "Io"),
        )
        comp[j] = own if j + 1 == n else shift_inertia(frames[j + 1], comp[j + 1], own, program, "c")
    return [c[0] for c in comp], [c[1] for c in comp], [c[2] for c in comp]


def mass_matrix_crba(
    robot: Robot, frames: list[JointFrame], composites: Composites, program: Program
) -> sp.Matrix:
    """M(q) of the rigid bodies plus reflected motor inertia, over the program's intermediates
    (`composites` from `composite_inertias`)."""
    n = robot.n
    mass, h, I = composites
    M = sp.zeros(n, n)
    for j in range(n):
        nf, ff = apply_inertia(mass[j], h[j], I[j], motion_subspace(robot.links[j]))
        nf, ff = program.let_vector(nf, "Fn"), program.let_vector(ff, "Ff")
        for i in range(j, -1, -1):
            if i < j:
                nf, ff = frames[i + 1].force_to_parent(nf, ff, program, "Ff")
                nf = program.let_vector(nf, "Fn")
            entry = project(motion_subspace(robot.links[i]), (nf, ff))
            if i == j:
                entry = entry + robot.links[j].motor.reflected_inertia
            M[i, j] = M[j, i] = program.let(entry, "M")
    return M


def gravity_composite(
    robot: Robot, frames: list[JointFrame], composites: Composites, program: Program
) -> list[sp.Expr]:
    """G(q) from the composite bodies: with g_k the gravitational acceleration in frame k
    (g_k = R_k^T g_{k-1}) and m^c_k, h^c_k the subtree's mass and first moment about origin k,

        G_k = a_k . (g_k x h^c_k)   (revolute: minus gravity's torque about joint k)
        G_k = -m^c_k (a_k . g_k)    (prismatic: minus gravity's force along joint k)

    which is dP/dq_k for P = -sum_i m_i g^T p_ci. One rotation per link and no inward
    force recursion, against a Newton-Euler pass with qd = qdd = 0."""
    mass, h, _ = composites
    g = v3.vec(robot.gravity)
    G: list[sp.Expr] = []
    for k, link in enumerate(robot.links):
        R = frames[k].R
        g = program.let_vector(v3.mul_t(R, g), f"gk{k + 1}_")  # type: ignore[assignment]
        a = v3.vec(link.axis)
        if link.joint == "revolute":
            G.append(v3.dot(a, v3.cross(g, h[k])))
        else:
            G.append(-v3._prod(mass[k], v3.dot(a, g)))
    return G
