"""Symbolic recursive Newton-Euler (slides 14-15), written into a straight-line program.

Every quantity of link i is expressed in link i's body frame. With
R_i = parent_R_i(q_i) and p_i the origin of body i in its parent's frame
(symdyn.model.robot), the outward recursion from a base at rest, gravity entered as
a base acceleration vd_0 = -g, is

    revolute:  w_i  = R_i^T w_{i-1} + a_i qd_i
               wd_i = R_i^T wd_{i-1} + (R_i^T w_{i-1}) x a_i qd_i + a_i qdd_i
               vd_i = R_i^T [wd_{i-1} x p_i + w_{i-1} x (w_{i-1} x p_i) + vd_{i-1}]
    prismatic: w_i = R_i^T w_{i-1},  wd_i = R_i^T wd_{i-1},
               vd_i = R_i^T [...] + 2 w_i x a_i qd_i + a_i qdd_i
    vc_i = wd_i x c_i + w_i x (w_i x c_i) + vd_i
    F_i = m_i vc_i,   N_i = I_i wd_i + w_i x I_i w_i   (about the centre of mass)

and the inward one, i = n .. 1,

    f_i = R_{i+1} f_{i+1} + F_i
    n_i = N_i + c_i x F_i + R_{i+1} n_{i+1} + p_{i+1} x R_{i+1} f_{i+1}
    tau_i = a_i . n_i (revolute) or a_i . f_i (prismatic)

where a_i is the joint axis (z for DH robots) and c_i the centre of mass.
Components are named as they are computed, and zero inputs (qd = 0 for M
and G, gravity off for M and V) fold away, so each pass costs O(n).

wd x r + w x (w x r) is computed as W r, W = [wd x] + [w x]^2, once per link for
both the centre of mass and the next joint's origin. For links whose inertia
tensor has products of inertia, N_i + c_i x F_i is formed about the body origin
instead (h = m c, I_o = I_c + m (c^T c 1 - c c^T)): F = m vd + W h and
N_o = I_o wd + w x I_o w + h x vd, which need neither vc nor c x F.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.robot import Link, Robot
from ..spatial import vectors as v3
from ..symbolic.program import Program
from .frames import JointFrame, joint_frames

__all__ = ["newton_euler", "origin_inertia"]


def origin_inertia(link: Link) -> v3.Mat:
    """I_o = I_c + m (c^T c 1 - c c^T): the inertia about the body origin (parallel axis)."""
    m = sp.sympify(link.mass)
    c = v3.vec(link.com)
    Ic = v3.mat(link.inertia)
    cc = v3.dot(c, c)
    return tuple(
        tuple(Ic[r][s] + v3._prod(m, (cc if r == s else 0) - v3._prod(c[r], c[s])) for s in range(3))
        for r in range(3)
    )  # type: ignore[return-value]


def _about_origin(link: Link) -> bool:
    """Whether the wrench is cheaper about the body origin: when the tensor about the centre
    of mass already has products of inertia, I_o is no denser and c x F disappears; for a
    diagonal tensor (published DH models) the centre-of-mass form is cheaper."""
    Ic = link.inertia
    return any(Ic[r, s] != 0 for r in range(3) for s in range(3) if r != s)


def _body_wrench(
    link: Link, W: v3.Mat, w: v3.Vec, wd: v3.Vec, vd: v3.Vec, program: Program, k: str
) -> tuple[v3.Vec, v3.Vec]:
    """Net force F and moment N about the body origin that accelerate the link (slide 15).

    Either about the centre of mass, F = m (W c + vd), N = I_c wd + w x I_c w + c x F,
    or about the origin with h = m c: F = m vd + W h, N = I_o wd + w x I_o w + h x vd."""
    m = sp.sympify(link.mass)
    c = v3.vec(link.com)
    if _about_origin(link):
        h = tuple(v3._prod(m, x) for x in c)
        I = origin_inertia(link)
        F = program.let_vector(v3.add(v3.scale(m, vd), v3.mul(W, h)), f"F{k}_")
        extra = v3.cross(h, vd)
    else:
        I = v3.mat(link.inertia)
        vc = program.let_vector(v3.add(v3.mul(W, c), vd), f"vc{k}_")
        F = program.let_vector(v3.scale(m, vc), f"F{k}_")
        extra = v3.cross(c, F)
    Iw = program.let_vector(v3.mul(I, w), f"Iw{k}_")
    N = program.let_vector(v3.add(v3.mul(I, wd), v3.cross(w, Iw), extra), f"N{k}_")
    return F, N


def _tilde(program: Program, w: v3.Vec, wd: v3.Vec, k: str) -> v3.Mat:
    """W = [wd x] + [w x]^2, so that wd x r + w x (w x r) = W r for any point r of the link."""
    sq = [program.let(v3._prod(w[j], w[j]), f"ww{k}_") for j in range(3)]
    xy, xz, yz = (program.let(v3._prod(w[a], w[b]), f"ww{k}_") for a, b in ((0, 1), (0, 2), (1, 2)))
    W = (
        (-v3._sum((sq[1], sq[2])), v3._sum((xy, -wd[2])), v3._sum((xz, wd[1]))),
        (v3._sum((xy, wd[2])), -v3._sum((sq[0], sq[2])), v3._sum((yz, -wd[0]))),
        (v3._sum((xz, -wd[1])), v3._sum((yz, wd[0])), -v3._sum((sq[0], sq[1]))),
    )
    return tuple(program.let_vector(row, f"W{k}_") for row in W)  # type: ignore[return-value]


def _outward(
    link: Link,
    frame: JointFrame,
    w: v3.Vec,
    wd: v3.Vec,
    vd: v3.Vec,
    W: v3.Mat,
    qd,
    qdd,
    program: Program,
    k: str,
) -> tuple[v3.Vec, v3.Vec, v3.Vec]:
    """w_i, wd_i, vd_i of link i from those of its parent (slide 15, body frames).

    The parent's W = [wd x] + [w x]^2 gives wd x p + w x (w x p) = W p.
    """
    R, p = frame.R, frame.p
    a = v3.vec(link.axis)
    vd_new = v3.mul_t(R, v3.add(v3.mul(W, p), vd))
    w_par = program.let_vector(v3.mul_t(R, w), f"wp{k}_")
    wd_par = v3.mul_t(R, wd)
    if link.joint == "revolute":
        w_new = program.let_vector(v3.add(w_par, v3.scale(qd, a)), f"w{k}_")
        wd_new = v3.add(wd_par, v3.cross(w_par, v3.scale(qd, a)), v3.scale(qdd, a))
    else:
        w_new = w_par
        wd_new = wd_par
        vd_new = v3.add(vd_new, v3.scale(2, v3.cross(w_new, v3.scale(qd, a))), v3.scale(qdd, a))
    return w_new, program.let_vector(wd_new, f"wd{k}_"), program.let_vector(vd_new, f"vd{k}_")


def newton_euler(
    robot: Robot,
    q: Sequence,
    qd: Sequence,
    qdd: Sequence,
    program: Program,
    *,
    gravity: bool = True,
    tag: str = "",
    rotations: list[JointFrame] | None = None,
) -> list[sp.Expr]:
    """Rigid-body joint efforts (no friction, no motor inertia) for the given state.

    `q`, `qd`, `qdd` may hold symbols or numbers (zeros fold away). The result
    is a list of expressions over the program's intermediates. `rotations`
    (per link, from `symdyn.algorithms.frames.joint_frames`) may be passed in to share them.
    """
    n = robot.n
    frames = rotations if rotations is not None else joint_frames(robot, q)
    zero: v3.Vec = (sp.S.Zero,) * 3  # type: ignore[assignment]
    w, wd = zero, zero
    W: v3.Mat = (zero, zero, zero)
    vd = program.let_vector(v3.neg(v3.vec(robot.gravity)), f"{tag}g") if gravity else zero
    forces: list[v3.Vec] = []
    moments: list[v3.Vec] = []
    for i, link in enumerate(robot.links):
        k = f"{tag}{i + 1}"
        w, wd, vd = _outward(link, frames[i], w, wd, vd, W, qd[i], qdd[i], program, k)
        W = _tilde(program, w, wd, k)
        F, N = _body_wrench(link, W, w, wd, vd, program, k)
        forces.append(F)
        moments.append(N)
    tau: list[sp.Expr] = [sp.S.Zero] * n
    f_next, n_next = zero, zero
    for i in reversed(range(n)):
        link = robot.links[i]
        k = f"{tag}{i + 1}"
        if i + 1 < n:
            n_par, f_par = frames[i + 1].force_to_parent(n_next, f_next, program, f"Rf{k}_")
            n_new = v3.add(moments[i], n_par)
            f_new = v3.add(f_par, forces[i])
        else:
            n_new = moments[i]
            f_new = forces[i]
        f_next = program.let_vector(f_new, f"f{k}_")
        n_next = program.let_vector(n_new, f"n{k}_")
        a = v3.vec(link.axis)
        tau[i] = v3.dot(a, n_next if link.joint == "revolute" else f_next)
    return tau
