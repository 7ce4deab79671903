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

from .program import Program
from .robot import Robot

__all__ = ["newton_euler"]


def _joint_rotation_and_origin(link, qi) -> tuple[sp.Matrix, sp.Matrix]:
    T = link.joint_transform(qi)
    return sp.Matrix(T.R), sp.Matrix(T.p)


def newton_euler(
    robot: Robot,
    q: Sequence,
    qd: Sequence,
    qdd: Sequence,
    program: Program,
    *,
    gravity: bool = True,
    tag: str = "",
    rotations: list[tuple[sp.Matrix, sp.Matrix]] | None = None,
) -> list[sp.Expr]:
    """Rigid-body joint efforts (no friction, no motor inertia) for the given state.

    `q`, `qd`, `qdd` may hold symbols or numbers (zeros fold away). The result
    is a list of expressions over the program's intermediates. `rotations`
    (R_i, p_i per link) may be passed in to share them across passes.
    """
    n = robot.n
    if rotations is None:
        rotations = [_joint_rotation_and_origin(link, qi) for link, qi in zip(robot.links, q, strict=True)]
    zero = sp.zeros(3, 1)
    w, wd = zero, zero
    vd = -sp.Matrix(robot.gravity) if gravity else zero
    vd = program.let_vector(vd, f"{tag}g") if gravity else vd
    forces: list[sp.Matrix] = []
    moments: list[sp.Matrix] = []
    for i, link in enumerate(robot.links):
        R, p = rotations[i]
        Rt = R.T
        a = sp.Matrix(link.axis)
        k = f"{tag}{i + 1}"
        vd_new = Rt * (wd.cross(p) + w.cross(w.cross(p)) + vd)
        w_par = program.let_vector(Rt * w, f"wp{k}_")
        if link.joint == "revolute":
            w_new = program.let_vector(w_par + a * qd[i], f"w{k}_")
            wd_new = program.let_vector(Rt * wd + w_par.cross(a * qd[i]) + a * qdd[i], f"wd{k}_")
        else:
            w_new = w_par
            wd_new = program.let_vector(Rt * wd, f"wd{k}_")
            vd_new = vd_new + 2 * w_new.cross(a * qd[i]) + a * qdd[i]
        w, wd = w_new, wd_new
        vd = program.let_vector(vd_new, f"vd{k}_")
        c = sp.Matrix(link.com)
        vc = program.let_vector(wd.cross(c) + w.cross(w.cross(c)) + vd, f"vc{k}_")
        I = sp.Matrix(link.inertia)
        Iw = program.let_vector(I * w, f"Iw{k}_")
        forces.append(program.let_vector(link.mass * vc, f"F{k}_"))
        moments.append(program.let_vector(I * wd + w.cross(Iw), f"N{k}_"))
    tau: list[sp.Expr] = [sp.S.Zero] * n
    f_next, n_next = zero, zero
    for i in reversed(range(n)):
        link = robot.links[i]
        k = f"{tag}{i + 1}"
        c = sp.Matrix(link.com)
        F = forces[i]
        if i + 1 < n:
            R1, p1 = rotations[i + 1]
            Rf = program.let_vector(R1 * f_next, f"Rf{k}_")
            Rn = R1 * n_next
            n_new = moments[i] + Rn + c.cross(F) + p1.cross(Rf)
            f_new = Rf + F
        else:
            n_new = moments[i] + c.cross(F)
            f_new = F
        f_next = program.let_vector(f_new, f"f{k}_")
        n_next = program.let_vector(n_new, f"n{k}_")
        a = sp.Matrix(link.axis)
        tau[i] = (a.T * (n_next if link.joint == "revolute" else f_next))[0]
    return tau
