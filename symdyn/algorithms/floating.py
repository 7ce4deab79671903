"""The Newton-Euler route on a floating base: the free flyer as a moving root of the recursions.

A floating robot (symdyn.model.free_flyer) has the base's twist v_b = (v, w) (linear velocity of
its origin and angular velocity, base frame) and its derivative a_b = (a, dw) among its velocities
and accelerations, ahead of the joints'. The recursions of symdyn.algorithms.newton_euler and
.crba run unchanged on the links, from a base that moves:

    w_0 = w,   wd_0 = dw,   vd_0 = a + w x v - R^T g

(vd_0: the classical acceleration of the base origin, gravity entered as a fictitious
acceleration, R = world_R_base of the normalised quaternion, symdyn.model.free_flyer). The base
rows of tau are the wrench on the base, force then moment about its origin in the base frame:
the base body's own Newton-Euler wrench plus what the links on the base push on it. Because v_b
and a_b are in the base frame, M and the velocity terms depend on the joint coordinates only; the
orientation enters through R^T g alone.

M by the CRBA: the base block is the composite inertia of the whole robot (base body included)
about the base origin, in Pinocchio's order [[m 1, -[h x]], [[h x], I]] (h = m c its first
moment); the base-joint block holds each joint's unit-acceleration force carried down to the base
frame (force rows, then moment rows). G: the joint rows from the composites with g_b = R^T g
(symdyn.algorithms.crba.gravity_composite) and the base rows (-m g_b, g_b x h) of the whole robot.

References: Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 9.3 (floating bases: the
RNEA and CRBA with a six-DOF root); Pinocchio's JointModelFreeFlyer (its conventions).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.free_flyer import quaternion_rotation
from ..model.robot import Robot
from ..model.topology import children
from ..spatial import vectors as v3
from ..spatial.inertia import SpatialInertia, body_inertia
from ..spatial.motion import Force
from ..symbolic.program import Program
from .coordinates import project_matrix, project_vector
from .crba import composite_inertias, gravity_composite, mass_matrix_crba, shift_inertia
from .floating_coriolis import floating_coriolis_matrix
from .floating_lagrange import floating_lagrange
from .frames import joint_frames
from .newton_euler import LinkAcceleration, body_wrench, newton_euler, tilde

__all__ = ["floating_newton_euler_terms", "floating_lagrange_terms", "base_gravity_vector", "inertia_efforts"]


def base_gravity_vector(robot: Robot, quaternion: Sequence, program: Program) -> v3.Vec:
    """g_b = R^T g: the robot's gravity in the frame of a base with orientation `quaternion`
    (qx, qy, qz, qw; the rotation of the normalised quaternion)."""
    R = quaternion_rotation(*quaternion)
    g = v3.vec(robot.gravity)
    g_b = [v3.sum_terms([R[r, c] * g[r] for r in range(3) if g[r] != 0]) for c in range(3)]
    return program.let_vector(tuple(g_b), "gb")


def _base_motion(
    v: Sequence, a: Sequence, g_b: v3.Vec | None, program: Program, tag: str
) -> LinkAcceleration:
    """(w, wd, vd) of the base origin, base frame: vd = a + w x v (- g_b with gravity)."""
    lin, w = v3.vec(v[:3]), v3.vec(v[3:])
    vd = v3.add(v3.vec(a[:3]), v3.cross(w, lin))
    if g_b is not None:
        vd = v3.sub(vd, g_b)
    return LinkAcceleration(w, v3.vec(a[3:]), program.let_vector(vd, f"{tag}vd0_"))


def _base_pass(robot: Robot, q_b, qd_b, qdd_b, base: LinkAcceleration, rot, program: Program, tag: str):
    """One Newton-Euler pass from a moving base: the bodies' joint efforts (nb) and the base rows
    (force, then moment; base frame) with the base body's own wrench."""
    pushed: list[Force] = []
    tau = newton_euler(
        robot, q_b, qd_b, qdd_b, program, tag=tag, rotations=rot, base=base, base_wrench=pushed
    )
    W = tilde(program, base.w, base.wd, f"{tag}b")
    own = body_wrench(robot.base_body, W, base, program, f"{tag}b")
    f = program.let_vector(v3.add(own.linear, pushed[0].linear), f"{tag}fb")
    n = program.let_vector(v3.add(own.angular, pushed[0].angular), f"{tag}nb")
    return tau, [*f, *n]


def _whole_robot(robot: Robot, rot, composites: list[SpatialInertia], program: Program) -> SpatialInertia:
    """The composite inertia of the whole robot, base body included, about the base origin."""
    body = robot.base_body
    own = body_inertia(body.mass, body.com, body.inertia)
    own = SpatialInertia(
        own.mass, program.let_vector(own.first_moment, "h"), program.let_symmetric(own.inertia, "Io")
    )
    for child in children(robot.parents, -1):
        own = shift_inertia(rot[child], composites[child], own, program, "c")
    return own


def _base_block(whole: SpatialInertia) -> list[list[sp.Expr]]:
    """[[m 1, -[h x]], [[h x], I]]: the spatial inertia about the base origin, linear rows first."""
    m, (hx, hy, hz), I = whole.mass, whole.first_moment, whole.inertia
    H = [[0, -hz, hy], [hz, 0, -hx], [-hy, hx, 0]]
    top = [[m if r == c else 0 for c in range(3)] + [-H[r][c] for c in range(3)] for r in range(3)]
    bottom = [[H[r][c] for c in range(3)] + [I[r][c] for c in range(3)] for r in range(3)]
    return top + bottom


def floating_newton_euler_terms(robot: Robot, q, qd, qdd, program: Program) -> dict[str, sp.Matrix]:
    """M and C (NV x NV; C by symdyn.algorithms.floating_coriolis), V, G, tau and the rigid-body
    bias (NV) of a floating robot by Newton-Euler and
    the composite bodies, over q (NQ symbols: base position, quaternion, joints), qd and qdd (NV:
    base twist or its derivative, then the joints'); friction and rotor inertia on the joints only.
    """
    n = robot.n
    joints_q, joints_qd, joints_qdd = list(q[7:]), list(qd[6:]), list(qdd[6:])
    q_b, qd_b = robot.body_positions(joints_q), robot.body_rates(joints_qd)
    qdd_b = robot.body_rates(joints_qdd)
    rot = joint_frames(robot, q_b)
    zeros = [0] * robot.nb
    g_b = base_gravity_vector(robot, list(q[3:7]), program)
    composites = composite_inertias(robot, rot, program)
    whole = _whole_robot(robot, rot, composites, program)
    columns: list[Force] = []
    M_b = mass_matrix_crba(robot, rot, composites, program, base_columns=columns)
    M = sp.zeros(n + 6, n + 6)
    M[:6, :6] = sp.Matrix(_base_block(whole))
    if n:  # (a single rigid body, n = 0, has the base block only)
        coupling = sp.Matrix([[*c.linear, *c.angular] for c in columns]).T  # 6 x nb, the bodies' joints
        M[:6, 6:] = coupling * robot.selection()
        M[6:, :6] = M[:6, 6:].T
        M[6:, 6:] = project_matrix(robot, M_b, program, "M")
    G_joints = gravity_composite(robot, rot, composites, program, g_base=g_b)
    G_base = [*(-whole.mass * g for g in g_b), *v3.cross(g_b, whole.first_moment)]
    zero6 = [0] * 6
    out = {"M": M, "G": sp.Matrix([*G_base, *project_vector(robot, G_joints, program, "G")])}
    out["C"] = floating_coriolis_matrix(robot, rot, list(qd[:6]), qd_b, program)
    for key, tag, a, gravity, accelerations in (
        ("V", "V", zero6, False, zeros),
        ("bias", "B", zero6, True, zeros),
        ("tau", "T", qdd[:6], True, qdd_b),
    ):
        base = _base_motion(qd[:6], a, g_b if gravity else None, program, tag)
        tau_b, rows = _base_pass(robot, q_b, qd_b, accelerations, base, rot, program, tag)
        if key == "tau":
            tau_b = [
                t + lk.motor.reflected_inertia * x for t, lk, x in zip(tau_b, robot.links, qdd_b, strict=True)
            ]
        out[key] = sp.Matrix([*rows, *project_vector(robot, tau_b, program, key)])
    return out


def inertia_efforts(robot: Robot, q, x, program: Program, tag: str = "X") -> list[sp.Expr]:
    """The part of M(q) x that depends on q, by one Newton-Euler pass at rest without gravity:
    NE(q, 0, x) (n entries; on a floating robot NV, x's base rows the base twist's rate, from the
    moving root above), the rotors' reflected inertia and the tendons' armature (constant in q) left
    out. So d(M(q) x)/dq = d NE(q, 0, x)/dq with x held: one recursion to differentiate, where the
    entries of M would be NV^2 (the impulse's derivative, symdyn.codegen.contact_functions)."""
    q = list(q)
    joints_q, joints_x = (q[7:], list(x[6:])) if robot.floating else (q, list(x))
    q_b, x_b = robot.body_positions(joints_q), robot.body_rates(joints_x)
    rot = joint_frames(robot, q_b)
    zeros = [0] * robot.nb
    if not robot.floating:
        tau_b = newton_euler(robot, q_b, zeros, x_b, program, gravity=False, tag=tag, rotations=rot)
        return project_vector(robot, tau_b, program, tag)
    base = _base_motion([0] * 6, list(x[:6]), None, program, tag)
    tau_b, rows = _base_pass(robot, q_b, zeros, x_b, base, rot, program, tag)
    return [*rows, *project_vector(robot, tau_b, program, tag)]


def floating_lagrange_terms(robot: Robot, q, qd, qdd, program: Program) -> dict[str, sp.Matrix]:
    """M, V, G, tau and the bias of a floating robot by the Lagrange route in the tangent space
    (symdyn.algorithms.floating_lagrange), and C from the bodies' Jacobians
    (symdyn.algorithms.floating_coriolis: the same matrix as the Newton-Euler route's)."""
    g_b = base_gravity_vector(robot, list(q[3:7]), program)
    out = floating_lagrange(robot, q, qd, qdd, g_b, program)
    rot = joint_frames(robot, robot.body_positions(list(q[7:])))
    out["C"] = floating_coriolis_matrix(robot, rot, list(qd[:6]), robot.body_rates(list(qd[6:])), program)
    return out
