"""The Lagrange route on a floating base, in the tangent space (Boltzmann-Hamel / Euler-Poincare).

The kinetic energy T = 1/2 nu^T M(q) nu with nu = [v, w, qd] (the base twist in the base frame,
then the joint rates) and M = sum_i m_i Jv_i^T Jv_i + Jw_i^T I_i Jw_i over the bodies, the base
body included: Jv_i, Jw_i the velocity of body i's centre of mass and its angular velocity per
unit nu, in body i's frame. With R_i = base_R_i and p_ci its centre of mass in the base frame
(forward kinematics), the base's columns are Jv = R_i^T [1, -[p_ci x]], Jw = [0, R_i^T]; the
joints' are the fixed-base body Jacobian (symdyn.algorithms.kinematics). The base pose does not
enter T. With p = M nu the momentum,

    joint rows:  d/dt (dT/dqd) - dT/dq + dU/dq = tau_joints   (Lagrange: q are coordinates)
    base rows:   d/dt (p_v, p_w) + (w x p_v, w x p_w + v x p_v) + grad U = (f, n)

(Euler-Poincare on SE(3) with the body twist, the ad* term; Boltzmann-Hamel), where
d/dt (M nu) = M nu' + sum_j dM/dq_j qd_j nu (M depends on the joints only) and the
left-trivialised gradient of U = -sum_i m_i g^T p_ci is (-m g_b, sum_i m_i g_b x p_ci) with
g_b = R^T g. The derivatives are taken through the program's intermediates (Program.diff).

References: Marsden and Ratiu, Introduction to Mechanics and Symmetry (1999), ch. 13 (the
Euler-Poincare equations); Greenwood, Advanced Dynamics (2003), sec. 4.3 (Boltzmann-Hamel).
"""

from __future__ import annotations

import sympy as sp

from ..model.robot import Robot
from ..symbolic.program import Program
from .kinematics import body_point_jacobian, forward_kinematics

__all__ = ["floating_lagrange"]


def _cross_matrix(p) -> sp.Matrix:
    return sp.Matrix([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])


def _body_term(
    mass, com_base, R, inertia, Jv_joints, Jw_joints, n: int, program: Program, k: str
) -> sp.Matrix:
    """m Jv^T Jv + Jw^T I Jw of one body over nu (NV = 6 + n)."""
    Rt = R.T
    Jv = sp.Matrix.hstack(Rt, -Rt * _cross_matrix(com_base), Jv_joints).applyfunc(
        lambda x: program.let(x, f"LJv{k}")
    )
    Jw = sp.Matrix.hstack(sp.zeros(3, 3), Rt, Jw_joints)
    return mass * (Jv.T * Jv) + Jw.T * sp.Matrix(inertia) * Jw


def floating_lagrange(robot: Robot, q, qd, qdd, g_b, program: Program) -> dict[str, sp.Matrix]:
    """M (NV x NV), V, G, tau and the rigid-body bias (NV) of a floating robot by the Lagrange route
    in the tangent space (module documentation); `g_b`: gravity in the base frame (3 entries)."""
    n = robot.n
    qj = list(q[7:])
    nu = sp.Matrix(qd)
    poses = forward_kinematics(robot, qj, program)
    body = robot.base_body
    zero = sp.zeros(3, n)
    M = _body_term(body.mass, list(body.com), sp.eye(3), body.inertia, zero, zero, n, program, "0_")
    mass = body.mass
    moment = sp.Matrix(body.com) * body.mass  # sum m_i p_ci, base frame
    for i, link in enumerate(robot.links):
        J = body_point_jacobian(robot, i, list(link.com), qj, program)
        pc = sp.Matrix(poses[i].apply(list(link.com)))
        R = sp.Matrix(poses[i].R)
        M += _body_term(link.mass, list(pc), R, link.inertia, J[:3, :], J[3:, :], n, program, f"{i + 1}_")
        mass += link.mass
        moment += link.mass * pc
    for link, c in zip(robot.links, robot.coordinates, strict=True):
        M[6 + c.index, 6 + c.index] += c.multiplier**2 * link.motor.reflected_inertia
    size = n + 6
    for r in range(size):
        for c in range(r, size):
            M[r, c] = M[c, r] = program.let(M[r, c], "LM")
    upper = [(r, c) for r in range(size) for c in range(r, size)]
    dM = []  # dM/dq_j per joint coordinate
    for j in range(n):
        derivs = program.diff([M[r, c] for r, c in upper], qj[j], f"LdM{j + 1}_")
        D = sp.zeros(size, size)
        for (r, c), d in zip(upper, derivs, strict=True):
            D[r, c] = D[c, r] = d
        dM.append(D)
    p = (M * nu).applyfunc(lambda x: program.let(x, "Lp"))
    Mdot_nu = sum((dM[j] * nu * nu[6 + j] for j in range(n)), sp.zeros(size, 1))
    V = Mdot_nu.copy()
    for j in range(n):
        V[6 + j] -= sp.Rational(1, 2) * (nu.T * dM[j] * nu)[0]
    v, w = sp.Matrix(nu[:3]), sp.Matrix(nu[3:6])
    pv, pw = sp.Matrix(p[:3]), sp.Matrix(p[3:6])
    ad = sp.Matrix.vstack(w.cross(pv), w.cross(pw) + v.cross(pv))
    for r in range(6):
        V[r] += ad[r]
    V = V.applyfunc(lambda x: program.let(x, "LV"))
    g = sp.Matrix(list(g_b))
    U = -(g.T * moment)[0]
    G_joints = [program.diff([U], x, "LdU")[0] for x in qj]
    G = sp.Matrix([*(-mass * g), *g.cross(moment), *G_joints])
    acc = M * sp.Matrix(qdd)
    return {"M": M, "V": V, "G": G, "bias": V + G, "tau": acc + V + G}
