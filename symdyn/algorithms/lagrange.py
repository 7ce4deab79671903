"""The Lagrange route: M from the link Jacobians, C from Christoffel symbols, G from the potential.

With Jv_i the Jacobian of link i's centre of mass, Jw_i its angular-velocity Jacobian,
both written in link i's own body frame (the body Jacobian, Murray, Li and Sastry (1994),
sec. 4.2), and I_i its inertia about the centre of mass in the same (body) axes, summed over
the nb links of the tree and taken over the n independent coordinates (a column is nonzero
only for the joints that support link i; a mimic joint q_j = s q_k + o adds s times its
column to q_k's, symdyn.algorithms.kinematics):

    M = sum_i m_i Jv_i^T Jv_i + Jw_i^T I_i Jw_i  (+ reflected motor inertia s^2 J)

the kinetic energy 1/2 qd^T M qd, which a rotation of the frame leaves unchanged; written in
the base frame (Spong et al.'s Jv, Jw and R_i I_i R_i^T) the same M carries every joint angle
below the link, including the first, only for them to cancel in the sum, which makes its
closed form (symdyn.algorithms.configuration_space) many times costlier to build.
    P = -sum_i m_i g^T p_ci                   (g: gravitational acceleration)
    G_k = dP/dq_k
    C_kj = sum_i 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k) qd_i

Derivatives are taken by forward-mode differentiation through the program's
named intermediates (symdyn.symbolic.program), never by expanding M.

References: Murray, Li, Sastry, A Mathematical Introduction to Robotic Manipulation (1994),
sec. 4.2 (M = sum J_i^T M_i J_i with body Jacobians); Spong, Hutchinson, Vidyasagar, Robot
Modeling and Control (2006), sec. 7.2
(kinetic and potential energy, M from the Jacobians) and sec. 7.3 (equations of motion,
Christoffel symbols); Craig, Introduction to Robotics (3rd ed., 2005), sec. 6.9 (Lagrangian
formulation). R. Grupen, "Dynamics" (2015) lists Lagrangian dynamics in its outline (slide 1)
and gives the resulting form tau = M qdd + V + G + F on slide 16.
"""

from __future__ import annotations

import sympy as sp

from ..model.robot import Robot
from ..symbolic.program import Program
from .kinematics import body_point_jacobian, forward_kinematics

__all__ = ["lagrange"]


def lagrange(robot: Robot, q: sp.Matrix, qd: sp.Matrix, program: Program) -> dict[str, sp.Matrix]:
    """M, C and G of the robot (rigid bodies plus motor inertia) by Lagrange's equations.

    Args:
        robot: the model, nb links in a tree, n independent joints.
        q, qd: the independent joint position and velocity symbols (n x 1); derivatives are
            taken by them.
        program: receives the named intermediates.

    Returns:
        {"M": n x n, "C": n x n, "G": n x 1}, joint space, over the program's intermediates;
        C is the Christoffel-symbol matrix (dM/dt - 2C skew-symmetric, Spong et al. sec. 7.5).
    """
    n = robot.n
    assert len(q) == len(qd) == n, (len(q), len(qd), n)
    poses = forward_kinematics(robot, list(q), program)
    M = sp.zeros(n, n)
    P = sp.S.Zero
    g = sp.Matrix(robot.base_gravity)
    for i, link in enumerate(robot.links):
        J = body_point_jacobian(robot, i, list(link.com), list(q), program)
        Jv = J[:3, :].applyfunc(lambda x, i=i: program.let(x, f"Jv{i + 1}_"))
        Jw = J[3:, :]
        M += link.mass * (Jv.T * Jv) + Jw.T * sp.Matrix(link.inertia) * Jw
        pc = poses[i].apply(list(link.com))
        P -= link.mass * (g.T * sp.Matrix(pc))[0]
    for link, c in zip(robot.links, robot.coordinates, strict=True):
        M[c.index, c.index] += c.multiplier**2 * link.motor.reflected_inertia
    for i in range(n):
        for j in range(i, n):
            M[i, j] = program.let(M[i, j], "M")
    for i in range(n):
        for j in range(i):
            M[i, j] = M[j, i]
    G = sp.Matrix([program.diff([P], q[k], "dP")[0] for k in range(n)])
    upper = [(r, c) for r in range(n) for c in range(r, n)]
    dM: list[dict[tuple[int, int], sp.Expr]] = []
    for k in range(n):
        derivs = program.diff([M[r, c] for r, c in upper], q[k], f"dM{k + 1}_")
        table = {}
        for (r, c), d in zip(upper, derivs, strict=True):
            table[(r, c)] = table[(c, r)] = d
        dM.append(table)
    C = sp.zeros(n, n)
    for k in range(n):
        for j in range(n):
            C[k, j] = sum(
                (
                    sp.Rational(1, 2) * (dM[i][(k, j)] + dM[j][(k, i)] - dM[k][(i, j)]) * qd[i]
                    for i in range(n)
                ),
                sp.S.Zero,
            )
    return {"M": M, "C": C, "G": G}
