"""Symbolic recursive Newton-Euler, written into a straight-line program.

Every quantity of link i is expressed in link i's body frame. With
R_i = parent_R_i(q_i) and p_i the origin of body i in its parent's frame
(symdyn.model.robot), the outward recursion from a base at rest, gravity entered as
a base acceleration vd_0 = -g, is (i-1 standing for the parent lambda(i) of a tree,
symdyn.model.topology)

    revolute:  w_i  = R_i^T w_{i-1} + a_i qd_i
               wd_i = R_i^T wd_{i-1} + (R_i^T w_{i-1}) x a_i qd_i + a_i qdd_i
               vd_i = R_i^T [wd_{i-1} x p_i + w_{i-1} x (w_{i-1} x p_i) + vd_{i-1}]
    prismatic: w_i = R_i^T w_{i-1},  wd_i = R_i^T wd_{i-1},
               vd_i = R_i^T [...] + 2 w_i x a_i qd_i + a_i qdd_i
    vc_i = wd_i x c_i + w_i x (w_i x c_i) + vd_i
    F_i = m_i vc_i,   N_i = I_i wd_i + w_i x I_i w_i   (about the centre of mass)

and the inward one, i = nb .. 1, summing over the children j of link i (the next link
j = i+1 of a chain; no term for a leaf),

    f_i = F_i + sum_j R_j f_j
    n_i = N_i + c_i x F_i + sum_j (R_j n_j + p_j x R_j f_j)
    tau_i = a_i . n_i (revolute) or a_i . f_i (prismatic)

where a_i is the joint axis (z for DH robots) and c_i the centre of mass.
Components are named as they are computed, and zero inputs (qd = 0 for M
and G, gravity off for M and V) fold away, so each pass costs O(n).

wd x r + w x (w x r) is computed as W r, W = [wd x] + [w x]^2, once per link for
both the centre of mass and the next joint's origin. For links whose inertia
tensor has products of inertia, N_i + c_i x F_i is formed about the body origin
instead (h = m c, I_o = I_c + m (c^T c 1 - c c^T)): F = m vd + W h and
N_o = I_o wd + w x I_o w + h x vd, which need neither vc nor c x F.

References: R. Grupen, "Dynamics" (2015), slides 14-15 (the outward and inward iterations
above); Craig, Introduction to Robotics (3rd ed., 2005), sec. 6.5 (iterative Newton-Euler
dynamic formulation); Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 5.3 (the same
recursion on spatial vectors, which symdyn.rnea implements numerically).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import sympy as sp

from ..model.robot import Link, Robot
from ..model.topology import children
from ..spatial import vectors as v3
from ..spatial.inertia import body_inertia
from ..spatial.motion import Force
from ..symbolic.program import Program
from .frames import JointFrame, joint_frames

__all__ = ["newton_euler", "outward", "tilde", "body_wrench", "LinkAcceleration"]


class LinkAcceleration(NamedTuple):
    """Angular velocity w, angular acceleration wd and acceleration vd of a body's origin,
    all of one body, in that body's frame."""

    w: v3.Vec
    wd: v3.Vec
    vd: v3.Vec


def _about_origin(link: Link) -> bool:
    """Whether the wrench is cheaper about the body origin: when the tensor about the centre
    of mass already has products of inertia, I_o is no denser and c x F disappears; for a
    diagonal tensor (published DH models) the centre-of-mass form is cheaper."""
    Ic = link.inertia
    return any(Ic[r, s] != 0 for r in range(3) for s in range(3) if r != s)


def body_wrench(link: Link, W: v3.Mat, motion: LinkAcceleration, program: Program, k: str) -> Force:
    """The net wrench (N, F) about the body origin that accelerates the link (slide 15), body frame.

    Either about the centre of mass, F = m (W c + vd), N = I_c wd + w x I_c w + c x F,
    or about the origin with h = m c: F = m vd + W h, N = I_o wd + w x I_o w + h x vd."""
    w, wd, vd = motion
    m = sp.sympify(link.mass)
    c = v3.vec(link.com)
    if _about_origin(link):
        _, h, I = body_inertia(m, c, link.inertia)
        F = program.let_vector(v3.add(v3.scale(m, vd), v3.mul(W, h)), f"F{k}_")
        extra = v3.cross(h, vd)
    else:
        I = v3.mat(link.inertia)
        vc = program.let_vector(v3.add(v3.mul(W, c), vd), f"vc{k}_")
        F = program.let_vector(v3.scale(m, vc), f"F{k}_")
        extra = v3.cross(c, F)
    Iw = program.let_vector(v3.mul(I, w), f"Iw{k}_")
    N = program.let_vector(v3.add(v3.mul(I, wd), v3.cross(w, Iw), extra), f"N{k}_")
    return Force(N, F)


def tilde(program: Program, w: v3.Vec, wd: v3.Vec, k: str) -> v3.Mat:
    """W = [wd x] + [w x]^2, so that wd x r + w x (w x r) = W r for any point r of the link."""
    sq = [program.let(v3.product(w[j], w[j]), f"ww{k}_") for j in range(3)]
    xy, xz, yz = (program.let(v3.product(w[a], w[b]), f"ww{k}_") for a, b in ((0, 1), (0, 2), (1, 2)))
    W = (
        (-v3.sum_terms((sq[1], sq[2])), v3.sum_terms((xy, -wd[2])), v3.sum_terms((xz, wd[1]))),
        (v3.sum_terms((xy, wd[2])), -v3.sum_terms((sq[0], sq[2])), v3.sum_terms((yz, -wd[0]))),
        (v3.sum_terms((xz, -wd[1])), v3.sum_terms((yz, wd[0])), -v3.sum_terms((sq[0], sq[1]))),
    )
    return tuple(program.let_vector(row, f"W{k}_") for row in W)  # type: ignore[return-value]


def outward(
    link: Link,
    frame: JointFrame,
    parent: LinkAcceleration,
    W_parent: v3.Mat,
    qd,
    qdd,
    program: Program,
    k: str,
) -> LinkAcceleration:
    """w_i, wd_i, vd_i of link i (frame i) from its parent's (frame lambda(i)): slide 15.

    The parent's W = [wd x] + [w x]^2 gives wd x p + w x (w x p) = W p.
    """
    R, p = frame.R, frame.p
    a = v3.vec(link.axis)
    vd_i = v3.mul_t(R, v3.add(v3.mul(W_parent, p), parent.vd))
    w_parent_i = program.let_vector(v3.mul_t(R, parent.w), f"wp{k}_")  # the parent's w, frame i
    wd_parent_i = v3.mul_t(R, parent.wd)
    if link.joint == "revolute":
        w_i = program.let_vector(v3.add(w_parent_i, v3.scale(qd, a)), f"w{k}_")
        wd_i = v3.add(wd_parent_i, v3.cross(w_parent_i, v3.scale(qd, a)), v3.scale(qdd, a))
    else:
        w_i = w_parent_i
        wd_i = wd_parent_i
        vd_i = v3.add(vd_i, v3.scale(2, v3.cross(w_i, v3.scale(qd, a))), v3.scale(qdd, a))
    return LinkAcceleration(w_i, program.let_vector(wd_i, f"wd{k}_"), program.let_vector(vd_i, f"vd{k}_"))


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
    base: LinkAcceleration | None = None,
    base_wrench: list[Force] | None = None,
) -> list[sp.Expr]:
    """Rigid-body joint efforts (no friction, no motor inertia) by recursive Newton-Euler.

    Grupen (2015), slides 14-15; Craig (2005), sec. 6.5; Featherstone (2008), sec. 5.3
    (on a kinematic tree: outward from each link's parent, inward summing the children).

    Args:
        robot: the model, nb links (bodies) in a tree.
        q, qd, qdd: nb joint positions, velocities and accelerations of the bodies; symbols,
            numbers or expressions (zeros fold away).
        program: receives the named intermediates.
        gravity: enter the robot's gravity (base frame) as the base acceleration vd_0 = -g.
        tag: prefix of the intermediates' names, to tell passes apart.
        rotations: `symdyn.algorithms.frames.joint_frames(robot, q)`, to share them.
        base: the base's motion (w, wd, vd of its origin, base frame; gravity included) when it
            moves (a floating base, symdyn.algorithms.floating); None: at rest, vd_0 = -g.
        base_wrench: receives the wrench (n, f) the links on the base exert on it, about its
            origin, base frame: sum_j (R_j n_j + p_j x R_j f_j, R_j f_j) over its children.

    Returns:
        nb joint efforts tau_i = a_i . n_i (revolute) or a_i . f_i (prismatic), with n_i, f_i
        the wrench the parent exerts on link i in frame i; expressions over the program's
        intermediates (body joint space).
    """
    nb = robot.nb
    assert len(q) == len(qd) == len(qdd) == nb, (len(q), len(qd), len(qdd), nb)
    parents = robot.parents
    frames = rotations if rotations is not None else joint_frames(robot, q)
    zero = v3.ZERO3
    if base is None:
        vd_0 = program.let_vector(v3.neg(v3.vec(robot.base_gravity)), f"{tag}g") if gravity else zero
        base = LinkAcceleration(zero, zero, vd_0)
    W_base = v3.ZERO33 if base.w == zero and base.wd == zero else tilde(program, base.w, base.wd, f"{tag}0")
    motions: list[LinkAcceleration] = []  # of link i, in frame i
    Ws: list[v3.Mat] = []
    wrenches: list[Force] = []  # net wrench of link i about its origin, frame i
    for i, link in enumerate(robot.links):
        k = f"{tag}{i + 1}"
        p = parents[i]
        parent, W_parent = (base, W_base) if p < 0 else (motions[p], Ws[p])
        motion = outward(link, frames[i], parent, W_parent, qd[i], qdd[i], program, k)
        W = tilde(program, motion.w, motion.wd, k)
        motions.append(motion)
        Ws.append(W)
        wrenches.append(body_wrench(link, W, motion, program, k))
    tau: list[sp.Expr] = [sp.S.Zero] * nb
    transmitted: list[Force] = [Force(zero, zero)] * nb  # the wrench on link i from its parent, frame i
    for i in reversed(range(nb)):
        link = robot.links[i]
        k = f"{tag}{i + 1}"
        carried = [
            frames[j].force_to_parent(transmitted[j], program, f"Rf{k}_") for j in children(parents, i)
        ]
        n_i = v3.add(wrenches[i].angular, *(c.angular for c in carried))
        f_i = v3.add(*(c.linear for c in carried), wrenches[i].linear)
        f = program.let_vector(f_i, f"f{k}_")
        transmitted[i] = Force(program.let_vector(n_i, f"n{k}_"), f)
        a = v3.vec(link.axis)
        tau[i] = v3.dot(a, transmitted[i].angular if link.joint == "revolute" else f)
    if base_wrench is not None:
        carried = [
            frames[j].force_to_parent(transmitted[j], program, f"Rf{tag}0_") for j in children(parents, -1)
        ]
        base_wrench.append(Force(v3.add(*(c.angular for c in carried)), v3.add(*(c.linear for c in carried))))
    return tau
