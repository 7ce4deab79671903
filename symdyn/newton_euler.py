"""Symbolic recursive Newton-Euler (slides 14-15), written into a straight-line program.

Every quantity of link i is expressed in link i's body frame. With
R_i = parent_R_i(q_i) and p_i the origin of body i in its parent's frame
(symdyn.robot), the outward recursion from a base at rest, gravity entered as
a base acceleration vd_0 = -g, is

    revolute:  w_i  = R_i^T w_{i-1} + a_i qd_i
               wd_i = R_i^T wd_{i-1} + (R_i^T w_{i-1}) x a_i qd_i + a_i qdd_i
               vd_i = R_i^T [wd_{i-1} x p_i + w_{i-1} x (w_{i-1} x p_i) + vd_{i-1}]
    prismatic: w_i = R_i^T w_{i-1},  wd_i = R_i^T wd_{i-1},
               vd_i = R_i^T [...] + 2 w_i x a_i qd_i + a_i qdd_i
    vc_i = wd_i x c_i + w_i x (w_i x c_i) + vd_i

with wd x r + w x (w x r) computed as W r, W = [wd x] + [w x]^2, once per link
for both the centre of mass and the next joint's origin
    F_i = m_i vc_i,   N_i = I_i wd_i + w_i x I_i w_i

and the inward one, i = n .. 1,

    f_i = R_{i+1} f_{i+1} + F_i
    n_i = N_i + R_{i+1} n_{i+1} + c_i x F_i + p_{i+1} x R_{i+1} f_{i+1}
    tau_i = a_i . n_i (revolute) or a_i . f_i (prismatic)

where a_i is the joint axis (z for DH robots) and c_i the centre of mass.
Components are named as they are computed, and zero inputs (qd = 0 for M
and G, gravity off for M and V) fold away, so each pass costs O(n).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from . import vectors as v3
from .program import Program
from .robot import Link, Robot

__all__ = ["newton_euler", "joint_frames"]

JointFrame = tuple[v3.Mat, v3.Vec]


def joint_frames(robot: Robot, q: Sequence) -> list[JointFrame]:
    """(R_i, p_i) per link: rotation and origin of body i in its parent's body frame."""
    out = []
    for link, qi in zip(robot.links, q, strict=True):
        T = link.joint_transform(qi)
        out.append((v3.mat(T.R), v3.vec(T.p)))
    return out


def _name(program: Program, v: v3.Vec, hint: str) -> v3.Vec:
    return tuple(program.let(x, hint) for x in v)  # type: ignore[return-value]


def _tilde(program: Program, w: v3.Vec, wd: v3.Vec, k: str) -> v3.Mat:
    """W = [wd x] + [w x]^2, so that wd x r + w x (w x r) = W r for any point r of the link."""
    sq = [program.let(v3._prod(w[j], w[j]), f"ww{k}_") for j in range(3)]
    xy, xz, yz = (program.let(v3._prod(w[a], w[b]), f"ww{k}_") for a, b in ((0, 1), (0, 2), (1, 2)))
    W = (
        (-v3._sum((sq[1], sq[2])), v3._sum((xy, -wd[2])), v3._sum((xz, wd[1]))),
        (v3._sum((xy, wd[2])), -v3._sum((sq[0], sq[2])), v3._sum((yz, -wd[0]))),
        (v3._sum((xz, -wd[1])), v3._sum((yz, wd[0])), -v3._sum((sq[0], sq[1]))),
    )
    return tuple(_name(program, row, f"W{k}_") for row in W)  # type: ignore[return-value]


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
    R, p = frame
    a = v3.vec(link.axis)
    vd_new = v3.mul_t(R, v3.add(v3.mul(W, p), vd))
    w_par = _name(program, v3.mul_t(R, w), f"wp{k}_")
    wd_par = v3.mul_t(R, wd)
    if link.joint == "revolute":
        w_new = _name(program, v3.add(w_par, v3.scale(qd, a)), f"w{k}_")
        wd_new = v3.add(wd_par, v3.cross(w_par, v3.scale(qd, a)), v3.scale(qdd, a))
    else:
        w_new = w_par
        wd_new = wd_par
        vd_new = v3.add(vd_new, v3.scale(2, v3.cross(w_new, v3.scale(qd, a))), v3.scale(qdd, a))
    return w_new, _name(program, wd_new, f"wd{k}_"), _name(program, vd_new, f"vd{k}_")


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
    (R_i, p_i per link, from `joint_frames`) may be passed in to share them.
    """
    n = robot.n
    frames = rotations if rotations is not None else joint_frames(robot, q)
    zero: v3.Vec = (sp.S.Zero,) * 3  # type: ignore[assignment]
    w, wd = zero, zero
    W: v3.Mat = (zero, zero, zero)
    vd = _name(program, v3.neg(v3.vec(robot.gravity)), f"{tag}g") if gravity else zero
    forces: list[v3.Vec] = []
    moments: list[v3.Vec] = []
    for i, link in enumerate(robot.links):
        k = f"{tag}{i + 1}"
        w, wd, vd = _outward(link, frames[i], w, wd, vd, W, qd[i], qdd[i], program, k)
        W = _tilde(program, w, wd, k)
        c = v3.vec(link.com)
        I = v3.mat(link.inertia)
        vc = _name(program, v3.add(v3.mul(W, c), vd), f"vc{k}_")
        Iw = _name(program, v3.mul(I, w), f"Iw{k}_")
        forces.append(_name(program, v3.scale(link.mass, vc), f"F{k}_"))
        moments.append(_name(program, v3.add(v3.mul(I, wd), v3.cross(w, Iw)), f"N{k}_"))
    tau: list[sp.Expr] = [sp.S.Zero] * n
    f_next, n_next = zero, zero
    for i in reversed(range(n)):
        link = robot.links[i]
        k = f"{tag}{i + 1}"
        c = v3.vec(link.com)
        F = forces[i]
        if i + 1 < n:
            R1, p1 = frames[i + 1]
            Rf = _name(program, v3.mul(R1, f_next), f"Rf{k}_")
            n_new = v3.add(moments[i], v3.mul(R1, n_next), v3.cross(c, F), v3.cross(p1, Rf))
            f_new = v3.add(Rf, F)
        else:
            n_new = v3.add(moments[i], v3.cross(c, F))
            f_new = F
        f_next = _name(program, f_new, f"f{k}_")
        n_next = _name(program, n_new, f"n{k}_")
        a = v3.vec(link.axis)
        tau[i] = v3.dot(a, n_next if link.joint == "revolute" else f_next)
    return tau
