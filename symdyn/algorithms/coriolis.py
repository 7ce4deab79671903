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

On a kinematic tree (symdyn.model.topology) m is the deeper of j and k when one supports
the other, and C_jk is an exact zero when neither does: qd_k then moves no body that
joint j carries, and M_jk, M_ji and M_ki do not depend on the other joint.

which is the Christoffel form C = 1/2 dV/dqd (Echeandia and Wensing 2021 reach
the same result through their matrices B_i). With the half-quantities
H = h^c / 2 and P = Idot^c / 2 this reads, for j >= k,

    C_kj = s_k^T Y_j,               Y_j = P_j s_j + s_j x* H_j + I^c_j psi_j
    C_jk = s_k^T A_j + psi_k^T F_j,  A_j = P_j s_j - s_j x* H_j,  F_j = I^c_j s_j

(the lower triangle uses the symmetry of I^c and Idot^c and
<a, b x* f> = -<b, a x* f>). Only the three forces Y_j, A_j and F_j travel
inward along the support of j, n <- R n + p x R f, f <- R f; nothing with an inertia is formed per
pair of joints, against one Newton-Euler tangent pass per column when C is
computed as 1/2 dV/dqd.

A zero-mass spatial inertia (h, I) carries P: for a body with first moment h
and rotational inertia I about its origin moving with (w, u),
Idot = (dh, dI) with dh = w x h + m u and dI = [w x] I - I [w x] - ([u x][h x] + [h x][u x])
(symdyn.spatial.inertia.inertia_rate).

References: Spong, Hutchinson, Vidyasagar, Robot Modeling and Control (2006), sec. 7.3
(Christoffel symbols) and sec. 7.5 (skew symmetry of dM/dt - 2C); Featherstone, Rigid Body
Dynamics Algorithms (2008), sec. 2.9 (the cross products x and x*) and sec. 2.13 (spatial
inertia); S. Echeandia and P. M. Wensing, "Numerical methods to compute the Coriolis matrix
and Christoffel symbols for rigid-body systems", J. Comput. Nonlinear Dyn. 16(9), 2021;
R. Grupen, "Dynamics" (2015), slide 16 (V = C qd in tau = M qdd + V + G + F).
"""

from __future__ import annotations

import sympy as sp

from ..model.robot import Robot
from ..model.topology import children
from ..spatial import vectors as v3
from ..spatial.inertia import SpatialInertia, apply_inertia, inertia_rate, scaled_inertia
from ..spatial.motion import Force, Motion, cross_force, cross_motion, project, spatial_add, spatial_sub
from ..symbolic.program import Program
from .crba import link_inertia, link_subspace, shift_inertia
from .frames import JointFrame

__all__ = ["coriolis_matrix_composite"]

_HALF = sp.Rational(1, 2)


def _let_motion(program: Program, v: Motion, hint: str) -> Motion:
    """Name the six components of a motion."""
    return Motion(program.let_vector(v.angular, hint), program.let_vector(v.linear, hint))


def _let_force(program: Program, f: Force, hint: str) -> Force:
    """Name the six components of a force."""
    return Force(program.let_vector(f.angular, hint), program.let_vector(f.linear, hint))


def _named_rate(inertia: SpatialInertia, v: Motion, program: Program, k: str) -> SpatialInertia:
    """The rate of change of a body's spatial inertia moving with v, every entry named."""
    rate = inertia_rate(inertia, v)
    dh = program.let_vector(rate.first_moment, f"Pd{k}_")
    return SpatialInertia(rate.mass, dh, program.let_symmetric(rate.inertia, f"PI{k}_"))


def coriolis_matrix_composite(
    robot: Robot, frames: list[JointFrame], composites: list[SpatialInertia], qd, program: Program
) -> sp.Matrix:
    """C(q, qd) with V = C qd and dM/dt - 2C skew-symmetric (the Christoffel-symbol matrix).

    See the module docstring for the recursion.

    Args:
        robot: the model, nb links in a tree.
        frames: `symdyn.algorithms.frames.joint_frames(robot, q)`.
        composites: `symdyn.algorithms.crba.composite_inertias(robot, frames, program)`,
            subtree inertias about each body origin, body axes.
        qd: nb joint velocities of the bodies (symbols or expressions).
        program: receives the named intermediates.

    Returns:
        The nb x nb matrix C over the program's intermediates (the bodies' joint space);
        C_jk is SymPy's zero unless j supports k or k supports j.
    """
    nb = robot.nb
    assert len(qd) == nb and len(composites) == nb, (len(qd), len(composites), nb)
    parents = robot.parents
    s = [link_subspace(link) for link in robot.links]  # s[i] in frame i
    # outward: body velocities v_i (frame i) and psi_k = v_k x s_k (frame k)
    vel: list[Motion] = []
    for i in range(nb):
        R, p = frames[i].R, frames[i].p
        w, u = vel[parents[i]] if parents[i] >= 0 else (v3.ZERO3, v3.ZERO3)  # the parent's, its frame
        u = v3.mul_t(R, v3.add(u, v3.cross(w, p)))
        w = v3.mul_t(R, w)
        w = program.let_vector(v3.add(w, v3.scale(qd[i], s[i].angular)), f"w{i + 1}_")
        u = program.let_vector(v3.add(u, v3.scale(qd[i], s[i].linear)), f"u{i + 1}_")
        vel.append(Motion(w, u))
    psi = [_let_motion(program, cross_motion(vel[k], s[k]), f"psi{k + 1}_") for k in range(nb)]
    # inward: half momentum H and half inertia rate P of every subtree (frame i)
    H: list[Force] = [Force(v3.ZERO3, v3.ZERO3)] * nb
    P: list[SpatialInertia] = [scaled_inertia(_HALF, link_inertia(link)) for link in robot.links]
    for i in reversed(range(nb)):
        k = str(i + 1)
        half_body = P[i]
        half = apply_inertia(half_body, vel[i])
        own = _named_rate(half_body, vel[i], program, k)
        for child in children(parents, i):
            half = spatial_add(half, frames[child].force_to_parent(H[child], program, f"RH{k}_"))
            own = shift_inertia(frames[child], P[child], own, program, f"P{k}_")
        H[i] = _let_force(program, half, f"H{k}_")
        P[i] = own
    C = sp.zeros(nb, nb)
    for j in reversed(range(nb)):
        k = str(j + 1)
        Ps = apply_inertia(P[j], s[j])
        sH = cross_force(s[j], H[j])
        Ipsi = apply_inertia(composites[j], psi[j])
        # the three forces of column j, in frame j, then carried down the support of j
        Y = _let_force(program, spatial_add(Ps, sH, Ipsi), f"Y{k}_")
        A = _let_force(program, spatial_sub(Ps, sH), f"A{k}_")
        F = _let_force(program, apply_inertia(composites[j], s[j]), f"F{k}_")
        C[j, j] = program.let(project(s[j], Y), "C")
        i = j
        while parents[i] >= 0:
            frame, i = frames[i], parents[i]
            Y, A, F = (
                _let_force(program, frame.force_to_parent(force, program, f"R{tag}{k}_"), f"{tag}{k}_")
                for tag, force in (("Y", Y), ("A", A), ("F", F))
            )
            C[i, j] = program.let(project(s[i], Y), "C")
            C[j, i] = program.let(v3.sum_terms((project(s[i], A), project(psi[i], F))), "C")
    return C
